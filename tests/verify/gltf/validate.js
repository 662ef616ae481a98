// Prints the Khronos glTF-Validator's JSON report of one .glb or .gltf file (argv[2]).
// Used by tests/verify/verify_outputs.py; exits 2 when the file cannot be read.
'use strict';
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

const file = process.argv[2];
if (!file) {
  console.error('usage: node validate.js FILE.glb');
  process.exit(2);
}
let data;
try {
  data = new Uint8Array(fs.readFileSync(file));
} catch (e) {
  console.error(`cannot read ${file}: ${e.message}`);
  process.exit(2);
}
validator
  .validateBytes(data, {
    uri: path.basename(file),
    maxIssues: 100,
    externalResourceFunction: () => Promise.reject(new Error('no external resources')),
  })
  .then((report) => console.log(JSON.stringify(report, null, 1)))
  .catch((e) => {
    console.error(`validator failed on ${file}: ${e}`);
    process.exit(2);
  });
