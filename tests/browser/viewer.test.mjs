// Drives the 3D viewer of a built report.html in Debian's chromium through playwright-core and
// checks what a person would see:
//
//   node tests/browser/viewer.test.mjs OUT/report.html [--screenshots DIR] [--prefix P]
//        [--no-field-checks]
//
// Asserted: no console error or warning and no page error; the canvas is not blank; its
// centre pixel is a shade of the elevation colour map (not the background); a mouse drag,
// the vertical exaggeration slider (keyboard), hiding the solid layer, the colour-by selector
// and the cross-section each change the image; hiding the solid removes its colour from the
// picture; after switching fields the centre pixel is a shade of that field's colour map; the
// cursor readout shows coordinates and an elevation inside the ranges of dsm-vertices.csv
// (read here, beside report.html) and says what the elevation is above. With geological
// units: hiding each removes its colour (the DSM and the borehole traces hidden meanwhile); the borehole traces show the logged units' colours;
// the cross-section fills each cut unit with its colour (and not with the filling off). With
// faults and engineering objects: hiding each removes its colour, the cross-section cuts the
// faults and fills each object's cut.
// Exit status 1 with the failed check on stderr.
import { chromium } from "playwright-core";
import { existsSync, mkdirSync, readFileSync } from "node:fs";
import { dirname, join, resolve } from "node:path";
import { pathToFileURL } from "node:url";

const args = process.argv.slice(2);
const report = args[0];
const shotDir = args.includes("--screenshots") ? args[args.indexOf("--screenshots") + 1] : null;
// File names of the screenshots start with this (e.g. "viewer-model-" for a geological model).
const shotPrefix = args.includes("--prefix") ? args[args.indexOf("--prefix") + 1] : "viewer-";
if (!report || !existsSync(report)) {
  console.error(`usage: node viewer.test.mjs OUT/report.html [--screenshots DIR] (no file ${report})`);
  process.exit(2);
}
const executablePath = process.env.CHROMIUM || "/usr/bin/chromium";
if (!existsSync(executablePath)) {
  console.error(`${executablePath} is missing: run .ci/verify-setup.sh (or set CHROMIUM)`);
  process.exit(2);
}

function fail(msg) {
  console.error(`FAIL ${msg}`);
  process.exitCode = 1;
  throw new Error(msg);
}
function ok(msg) {
  console.log(`ok   ${msg}`);
}

// The vertex table of the same build: the independent range for the readout.
const csv = readFileSync(join(dirname(report), "dsm-vertices.csv"), "utf8").trim().split("\n");
const head = csv[0].split(",");
const col = (name) => head.indexOf(name);
const range = { x: [Infinity, -Infinity], y: [Infinity, -Infinity], z: [Infinity, -Infinity] };
for (const line of csv.slice(1)) {
  const v = line.split(",").map(Number);
  for (const [k, c] of [["x", col("x")], ["y", col("y")], ["z", col("elevation_uk")]]) {
    range[k][0] = Math.min(range[k][0], v[c]);
    range[k][1] = Math.max(range[k][1], v[c]);
  }
}

// Chromium 137+ no longer falls back to software WebGL silently: with --disable-gpu,
// --enable-unsafe-swiftshader opts in (the page is a local, trusted file).
const browser = await chromium.launch({
  executablePath,
  args: ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    "--enable-unsafe-swiftshader"],
});
const problems = [];
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 900 } });
  page.on("console", (m) => {
    // Software GL reports every read-back of the canvas as a performance notice; it is the
    // browser's, not the page's, and says nothing about the page.
    if (/GL Driver Message \(OpenGL, Performance/.test(m.text())) return;
    if (m.type() === "error" || m.type() === "warning") problems.push(`console ${m.type()}: ${m.text()}`);
  });
  page.on("pageerror", (e) => problems.push(`page error: ${e.message}`));
  page.on("requestfailed", (r) => problems.push(`failed request: ${r.url()}`));
  const t0 = Date.now();
  await page.goto(pathToFileURL(resolve(report)).href);
  await page.waitForSelector("#tmv[data-ready='1']", { timeout: 120000 }).catch(() =>
    fail(`the viewer did not draw within 120 s; ${problems.join(" | ") || "no console message"}`));
  ok(`the viewer drew its first frame ${((Date.now() - t0) / 1000).toFixed(2)} s after navigation`);
  const canvas = page.locator("#tmv-canvas");
  await canvas.scrollIntoViewIfNeeded();
  const box = await canvas.boundingBox();
  const centre = [box.x + box.width / 2, box.y + box.height / 2];
  const scene = await page.evaluate(() => JSON.parse(document.getElementById("tmv-data").textContent));

  // The canvas's pixels after the next frame, kept in the page under `name`: the centre
  // pixel, the background (corner) colour and colour statistics come back.
  async function snapshot(name) {
    return page.evaluate(async (name) => {
      const root = document.getElementById("tmv");
      for (let i = 0; i < 3; i++) await new Promise((r) => requestAnimationFrame(r));
      const c = document.getElementById("tmv-canvas");
      const two = document.createElement("canvas");
      two.width = c.width; two.height = c.height;
      const g = two.getContext("2d");
      g.drawImage(c, 0, 0);
      const d = g.getImageData(0, 0, c.width, c.height).data;
      (window.__snaps = window.__snaps || {})[name] = d;
      const bg = [d[0], d[1], d[2]];
      let other = 0; const colours = new Set();
      for (let i = 0; i < d.length; i += 4) {
        if (Math.abs(d[i] - bg[0]) + Math.abs(d[i + 1] - bg[1]) + Math.abs(d[i + 2] - bg[2]) > 6) other++;
        if (i % 40 === 0) colours.add((d[i] << 16) | (d[i + 1] << 8) | d[i + 2]);
      }
      const k = 4 * (Math.floor(c.height / 2) * c.width + Math.floor(c.width / 2));
      return { name, frames: Number(root.dataset.frames), centre: [d[k], d[k + 1], d[k + 2]], bg,
        nonBackground: other / (d.length / 4), colours: colours.size };
    }, name);
  }
  // The fraction of pixels that differ between two snapshots.
  async function changed(a, b) {
    return page.evaluate(([a, b]) => {
      const x = window.__snaps[a], y = window.__snaps[b];
      let n = 0;
      for (let i = 0; i < x.length; i += 4) {
        if (Math.abs(x[i] - y[i]) + Math.abs(x[i + 1] - y[i + 1]) + Math.abs(x[i + 2] - y[i + 2]) > 12) n++;
      }
      return n / (x.length / 4);
    }, [a.name, b.name]);
  }
  // Pixels of a snapshot that are a shade s * rgb of one colour (within 3 per channel) and,
  // when `others` are given, not also a shade of one of them (dark shades of two colours can
  // coincide: the faulted example's colluvium and marl).
  async function countShade(snap, rgb, others = []) {
    return page.evaluate(([name, rgb, others]) => {
      const d = window.__snaps[name];
      const shade = (i, c) => {
        const s = (d[i] * c[0] + d[i + 1] * c[1] + d[i + 2] * c[2]) / (c[0] ** 2 + c[1] ** 2 + c[2] ** 2);
        return s > 0.1 && Math.abs(d[i] - s * c[0]) <= 3 && Math.abs(d[i + 1] - s * c[1]) <= 3
          && Math.abs(d[i + 2] - s * c[2]) <= 3;
      };
      let n = 0;
      for (let i = 0; i < d.length; i += 4) {
        if (shade(i, rgb) && !others.some((c) => shade(i, c))) n++;
      }
      return n;
    }, [snap.name, rgb, others]);
  }
  // How far a pixel is from the nearest shade s * map(t) of a colour map (max channel error).
  function offMap(px, anchors) {
    let best = Infinity;
    for (let i = 0; i <= 1000; i++) {
      const t = (i / 1000) * (anchors.length - 1), j = Math.min(Math.floor(t), anchors.length - 2), f = t - j;
      const m = [0, 1, 2].map((c) => anchors[j][c] + (anchors[j + 1][c] - anchors[j][c]) * f);
      const s = Math.min(1.05, Math.max(0.15, (px[0] * m[0] + px[1] * m[1] + px[2] * m[2]) / (m[0] ** 2 + m[1] ** 2 + m[2] ** 2)));
      best = Math.min(best, Math.max(...[0, 1, 2].map((c) => Math.abs(px[c] - s * m[c]))));
    }
    return best;
  }
  async function shot(name) {
    if (!shotDir) return;
    mkdirSync(shotDir, { recursive: true });
    const file = join(shotDir, name.replace(/^viewer-/, shotPrefix));
    await page.locator("#tmv").screenshot({ path: file });
    ok(`screenshot ${file}`);
  }

  const first = await snapshot("first");
  if (first.nonBackground < 0.05 || first.colours < 50) {
    fail(`the canvas is blank: ${(100 * first.nonBackground).toFixed(1)} % non-background, ${first.colours} colours`);
  }
  ok(`the canvas is not blank: ${(100 * first.nonBackground).toFixed(1)} % non-background pixels, ${first.colours} colours (sampled)`);
  const elev = scene.fields.elevation.colours;
  const bgOff = Math.max(...[0, 1, 2].map((c) => Math.abs(first.centre[c] - first.bg[c])));
  const centreOff = offMap(first.centre, elev);
  if (bgOff < 10 || centreOff > 6) {
    fail(`the centre pixel ${first.centre} is not terrain-coloured (${centreOff.toFixed(1)} off the elevation map, ${bgOff} from the background ${first.bg})`);
  }
  ok(`the centre pixel ${first.centre} is a shade of the elevation colour map (within ${centreOff.toFixed(1)}), not the background ${first.bg}`);
  await shot("viewer-elevation.png");

  // Cursor readout at the centre.
  await page.mouse.move(centre[0] - 5, centre[1] - 5);
  await page.mouse.move(centre[0], centre[1]);
  await page.waitForSelector("#tmv-readout[data-easting]", { timeout: 10000 }).catch(async () =>
    fail(`no cursor readout: ${await page.textContent("#tmv-readout")}`));
  const ro = await page.evaluate(() => {
    const r = document.getElementById("tmv-readout");
    return { text: r.textContent, e: +r.dataset.easting, n: +r.dataset.northing, z: +r.dataset.elevation };
  });
  const inside = (v, [a, b], tol) => v >= a - tol && v <= b + tol;
  if (!/E \d/.test(ro.text) || !/N \d/.test(ro.text) || !/elevation \d/.test(ro.text)
    || !inside(ro.e, range.x, 1e-3) || !inside(ro.n, range.y, 1e-3) || !inside(ro.z, range.z, 1e-3)
    || !scene.heights || !ro.text.includes(scene.heights)) {
    fail(`the readout "${ro.text}" is not a point of the DSM (x ${range.x}, y ${range.y}, z ${range.z} in dsm-vertices.csv)`);
  }
  ok(`cursor readout: "${ro.text}"`);

  // A drag orbits.
  await page.mouse.down();
  for (let i = 1; i <= 10; i++) await page.mouse.move(centre[0] + 14 * i, centre[1] + 3 * i);
  await page.mouse.up();
  const dragged = await snapshot("dragged");
  const dDrag = await changed(first, dragged);
  if (dDrag < 0.02) fail(`a drag changed only ${(100 * dDrag).toFixed(2)} % of the pixels`);
  ok(`a mouse drag changed ${(100 * dDrag).toFixed(1)} % of the pixels`);

  // The exaggeration slider, by keyboard.
  await page.focus("#tmv-exag");
  for (let i = 0; i < 6; i++) await page.keyboard.press("ArrowRight");
  const exag = await page.inputValue("#tmv-exag");
  const exaggerated = await snapshot("exaggerated");
  const dExag = await changed(dragged, exaggerated);
  if (exag !== "4" || dExag < 0.02) fail(`the exaggeration slider (now ${exag}) changed ${(100 * dExag).toFixed(2)} % of the pixels`);
  ok(`vertical exaggeration ${exag}x changed ${(100 * dExag).toFixed(1)} % of the pixels`);

  // Hiding each geological unit (a project with [geology]): the unit with the most pixels of
  // its colour in view, then every other unit, each changes the picture and removes its colour.
  // The DSM surface (whose colours may be shades of a unit's) is hidden meanwhile.
  const units = scene.layers.filter((l) => l.name.startsWith("unit "));
  if (units.length) {
    const dsmInput = page.locator(`input[data-layer="${scene.layers[0].name}"]`);
    await dsmInput.uncheck();
    // The borehole traces are drawn in the units' colours: hidden too meanwhile.
    const traceLayer = scene.layers.find((l) => l.name.startsWith("borehole traces"));
    if (traceLayer) await page.locator(`input[data-layer="${traceLayer.name}"]`).uncheck();
    const noDsm = await snapshot("noDsm");
    let best = null;
    for (const u of units) {
      const n = await countShade(noDsm, u.colour);
      if (!best || n > best.n) best = { u, n };
    }
    for (const u of [best.u, ...units.filter((x) => x !== best.u)]) {
      const others = units.filter((x) => x.colour.join() !== u.colour.join()).map((x) => x.colour);
      const before = await countShade(noDsm, u.colour, others);
      const input = page.locator(`input[data-layer="${u.name}"]`);
      await input.uncheck();
      const hidden = await snapshot(`hidden-${u.name}`);
      const d = await changed(noDsm, hidden);
      const after = await countShade(hidden, u.colour, others);
      if (u === best.u && (d < 0.005 || before < 500 || after > 0.1 * before)) {
        fail(`hiding "${u.name}" changed ${(100 * d).toFixed(2)} % of the pixels; its pixels ${before} -> ${after}`);
      }
      // (The palette repeats after 12 units: a colour shared with another unit is not checked.)
      const unique = units.filter((x) => x.colour.join() === u.colour.join()).length === 1;
      if (unique && before >= 500 && after > 0.1 * before) fail(`hiding "${u.name}" left ${after} of its ${before} pixels`);
      if (u === best.u) ok(`hiding "${u.name}" changed ${(100 * d).toFixed(1)} % of the pixels; its pixels ${before} -> ${after}`);
      await input.check();
    }
    ok(`hiding any of the ${units.length} units removes its colour from the picture`);
    if (traceLayer) await page.locator(`input[data-layer="${traceLayer.name}"]`).check();

    // The boreholes as traces coloured by logged unit: with the units hidden, at least two
    // units' colours show along the holes, and go when the traces are hidden.
    const traces = scene.layers.find((l) => l.name.startsWith("borehole traces"));
    if (!traces || !traces.vertex_colours) fail("the scene has no borehole traces with vertex colours");
    for (const u of units) await page.locator(`input[data-layer="${u.name}"]`).uncheck();
    const holesOnly = await snapshot("holesOnly");
    const traceInput = page.locator(`input[data-layer="${traces.name}"]`);
    await traceInput.uncheck();
    const noTraces = await snapshot("noTraces");
    const seen = [];
    for (const u of units) {
      const unique = units.filter((x) => x.colour.join() === u.colour.join()).length === 1;
      const n = await countShade(holesOnly, u.colour), m = await countShade(noTraces, u.colour);
      if (unique && n >= 100 && m <= 0.1 * n) seen.push(`${u.name} ${n} -> ${m}`);
    }
    if (seen.length < Math.min(2, units.length)) {
      fail(`the borehole traces show fewer than two units' colours (pixels with -> without traces: ${seen.join(", ") || "none"})`);
    }
    ok(`borehole traces in the logged units' colours (pixels with -> without traces): ${seen.join(", ")}`);
    await traceInput.check();
    for (const u of units) await page.locator(`input[data-layer="${u.name}"]`).check();

    // Cut units capped: with the cross-section on, each cut unit's face is filled with its
    // colour, unshaded (exactly the colour, which lit or back faces reach only where a face
    // looks straight at the light); turning the filling off removes those pixels.
    await page.check("#tmv-clip");
    const capped = await snapshot("capped");
    await page.uncheck("#tmv-cap");
    const uncapped = await snapshot("uncapped");
    const exact = (snap, rgb) => page.evaluate(([name, rgb]) => {
      const d = window.__snaps[name];
      let n = 0;
      for (let i = 0; i < d.length; i += 4) {
        if (Math.abs(d[i] - rgb[0]) <= 3 && Math.abs(d[i + 1] - rgb[1]) <= 3 && Math.abs(d[i + 2] - rgb[2]) <= 3) n++;
      }
      return n;
    }, [snap.name, rgb]);
    const caps = [];
    for (const u of units) {
      const n = await exact(capped, u.colour), m = await exact(uncapped, u.colour);
      if (n >= 300 && m <= 0.2 * n) caps.push(`${u.name} ${n} -> ${m}`);
    }
    if (caps.length < Math.min(2, units.length)) {
      fail(`the cross-section fills fewer than two cut units (pixels of the exact unit colour, filled -> not: ${caps.join(", ") || "none"})`);
    }
    ok(`the cross-section fills the cut units with their colours (exact-colour pixels, filled -> not): ${caps.join(", ")}`);
    await page.check("#tmv-cap");
    await page.uncheck("#tmv-clip");
    await dsmInput.check();
    const unitsBack = await snapshot("unitsBack");
    if (await changed(exaggerated, unitsBack) > 0.001) fail("showing the units again did not restore the picture");
    const holes = scene.layers.find((l) => l.name.startsWith("boreholes"));
    if (!holes || holes.vertices < 2) fail("the scene has no borehole collars");
    ok(`${holes.name}: ${holes.vertices} points`);

    if (shotDir) {
      await page.click("#tmv-reset");
      await snapshot("unitsReset");
      await shot("viewer-units.png");
      // The units cut by the cross-section, filled, the DSM surface hidden.
      await dsmInput.uncheck();
      await page.check("#tmv-clip");
      await snapshot("unitsSection");
      await shot("viewer-units-section.png");
      await page.uncheck("#tmv-clip");
      // The borehole traces alone (the units hidden).
      for (const u of units) await page.locator(`input[data-layer="${u.name}"]`).uncheck();
      await snapshot("tracesOnly");
      await shot("viewer-boreholes.png");
      for (const u of units) await page.locator(`input[data-layer="${u.name}"]`).check();
      await dsmInput.check();
    }
  }

  // Hiding the solid layer (shown at first unless the geological units fill it: then it is
  // shown in their place for this check, and the units come back after it).
  const solidLayer = scene.layers.find((l) => l.name.startsWith("solid"));
  if (!solidLayer) fail("the scene has no solid layer");
  const solidInput = page.locator(`input[data-layer="${solidLayer.name}"]`);
  let solidBase = exaggerated;
  if (!solidLayer.visible) {
    await solidInput.check();
    for (const u of units) await page.locator(`input[data-layer="${u.name}"]`).uncheck();
    solidBase = await snapshot("solidBase");
  }
  const solidRgb = solidLayer.colour;
  const withSolid = await countShade(solidBase, solidRgb);
  await solidInput.uncheck();
  const noSolid = await snapshot("noSolid");
  const dSolid = await changed(solidBase, noSolid);
  const withoutSolid = await countShade(noSolid, solidRgb);
  if (dSolid < 0.005 || withSolid < 500 || withoutSolid > 0.1 * withSolid) {
    fail(`hiding "${solidLayer.name}" changed ${(100 * dSolid).toFixed(2)} % of the pixels; solid-coloured pixels ${withSolid} -> ${withoutSolid}`);
  }
  ok(`hiding "${solidLayer.name}" changed ${(100 * dSolid).toFixed(1)} % of the pixels; solid-coloured pixels ${withSolid} -> ${withoutSolid}`);
  await solidInput.check();
  let solidBack = await snapshot("solidBack");
  if (await changed(solidBase, solidBack) > 0.001) fail("showing the solid again did not restore the picture");
  ok("showing the solid again restores the picture");
  if (!solidLayer.visible) {
    await solidInput.uncheck();
    for (const u of units) await page.locator(`input[data-layer="${u.name}"]`).check();
    solidBack = await snapshot("solidBack2");
  }

  // Colour by the other fields (not with --no-field-checks: a DSM whose samples lie on a
  // plane, the faulted examples', has a kriging standard deviation of zero everywhere and
  // nothing for these checks to see).
  let prev = solidBack;
  const fieldChecks = args.includes("--no-field-checks") ? [] : ["kriging_std", "uk_minus_idw"];
  for (const key of fieldChecks) {
    if (!scene.fields[key]) fail(`the colour-by selector has no ${key}`);
    await page.selectOption("#tmv-field", key);
    const s = await snapshot(key);
    const d = await changed(prev, s);
    const off = offMap(s.centre, scene.fields[key].colours);
    if (d < 0.02 || off > 6) {
      fail(`colour by ${key}: ${(100 * d).toFixed(2)} % of the pixels changed, centre ${s.centre} ${off.toFixed(1)} off its map`);
    }
    ok(`colour by ${key} changed ${(100 * d).toFixed(1)} % of the pixels; centre ${s.centre} on its map (within ${off.toFixed(1)})`);
    prev = s;
    if (key === "kriging_std") {
      // The README's picture from the first view; the next field is compared with it.
      await page.click("#tmv-reset");
      prev = await snapshot("reset-std");
      await shot("viewer-kriging-std.png");
    }
  }

  // The cross-section plane.
  await page.selectOption("#tmv-field", "elevation");
  await page.check("#tmv-clip");
  const cut = await snapshot("cut");
  const dCut = await changed(prev, cut);
  if (dCut < 0.02) fail(`the cross-section changed only ${(100 * dCut).toFixed(2)} % of the pixels`);
  ok(`the cross-section changed ${(100 * dCut).toFixed(1)} % of the pixels`);
  await page.click("#tmv-reset");
  await snapshot("reset");
  await shot("viewer-cross-section.png");

  // Faults and engineering objects (a faulted model, objects cut in): with everything else
  // hidden, hiding each removes its colour; the cross-section cuts the faults (fewer of
  // their pixels) and fills each object's cut in its colour (not with the filling off).
  const sheetRe = /^(fault|tunnel|excavation|structure) /;
  const setClip = (v) => page.evaluate((v) => {
    const e = document.getElementById("tmv-clip-pos");
    e.value = String(v);
    e.dispatchEvent(new Event("input"));
  }, v);
  const sheets = scene.layers.filter((l) => sheetRe.test(l.name));
  if (sheets.length) {
      // From the first view (the drag turned a fault edge-on), the cross-section off, each
    // sheet alone (the others would hide it: the tunnel lies behind F1).
    await page.uncheck("#tmv-clip");
    await page.click("#tmv-reset");
    const viewBase = await snapshot("sheetsBase");
    const others = scene.layers.filter((l) => !sheetRe.test(l.name) && l.visible);
    for (const l of [...others, ...sheets]) await page.locator(`input[data-layer="${l.name}"]`).uncheck();
    const seen = [];
    for (const l of sheets) {
      const input = page.locator(`input[data-layer="${l.name}"]`);
      await input.check();
      const shown = await snapshot(`shown-${l.name}`);
      const before = await countShade(shown, l.colour);
      await input.uncheck();
      const hidden = await snapshot(`hidden-${l.name}`);
      const after = await countShade(hidden, l.colour);
      if (before < 100 || after > 0.1 * before) fail(`hiding "${l.name}" took its pixels ${before} -> ${after}`);
      seen.push(`${l.name} ${before} -> ${after}`);
    }
    for (const l of sheets) await page.locator(`input[data-layer="${l.name}"]`).check();
    ok(`hiding each fault or object (shown alone) removes its colour (pixels shown -> hidden): ${seen.join(", ")}`);
    const faults = sheets.filter((l) => l.name.startsWith("fault "));
    const objects = sheets.filter((l) => !l.name.startsWith("fault "));
    const count = async (snap, ls) => {
      let n = 0;
      for (const l of ls) n += await countShade(snap, l.colour);
      return n;
    };
    if (faults.length) {
      for (const l of objects) await page.locator(`input[data-layer="${l.name}"]`).uncheck();
      const whole = await snapshot("faultsWhole");
      await page.check("#tmv-clip");
      const cutFaults = await snapshot("faultsCut");
      const [n, m] = [await count(whole, faults), await count(cutFaults, faults)];
      if (m > 0.9 * n || m < 0.05 * n) fail(`the cross-section left ${m} of the faults' ${n} pixels`);
      ok(`the cross-section cuts the faults: their pixels ${n} -> ${m}`);
      await page.uncheck("#tmv-clip");
      for (const l of objects) await page.locator(`input[data-layer="${l.name}"]`).check();
    }
    if (objects.length) {
      // The section through the middle of the largest object (the viewer's plane spans the
      // box of every layer's positions, as the slider does).
      // (Each layer's bounding box: [lo, hi] per axis.)
      const box = (l) => {
        const b = Buffer.from(l.positions, "base64");
        const p = new Float32Array(b.buffer.slice(b.byteOffset, b.byteOffset + b.length));
        const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
        for (let i = 0; i < p.length; i += 3) {
          for (let k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], p[i + k]); hi[k] = Math.max(hi[k], p[i + k]); }
        }
        return [lo, hi];
      };
      const all = scene.layers.filter((l) => l.vertices > 0).map(box);
      const [xlo, xhi] = [Math.min(...all.map((b) => b[0][0])), Math.max(...all.map((b) => b[1][0]))];
      // The object of the largest box, cut across x (the north-south plane).
      const size = (l) => { const [lo, hi] = box(l); return (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]); };
      const big = objects.reduce((a, b) => (size(b) > size(a) ? b : a));
      const [blo, bhi] = box(big).map((c) => c[0]);
      for (const l of faults) await page.locator(`input[data-layer="${l.name}"]`).uncheck();
      await page.check("#tmv-clip");
      await page.selectOption("#tmv-clip-axis", "0");
      await setClip(Math.round(1000 * (0.5 * (blo + bhi) - xlo) / (xhi - xlo)));
      const capped = await snapshot("objectsCapped");
      await page.uncheck("#tmv-cap");
      const open = await snapshot("objectsOpen");
      const exact = (snap, rgb) => page.evaluate(([name, rgb]) => {
        const d = window.__snaps[name];
        let n = 0;
        for (let i = 0; i < d.length; i += 4) {
          if (Math.abs(d[i] - rgb[0]) <= 3 && Math.abs(d[i + 1] - rgb[1]) <= 3 && Math.abs(d[i + 2] - rgb[2]) <= 3) n++;
        }
        return n;
      }, [snap.name, rgb]);
      const [n, m] = [await exact(capped, big.colour), await exact(open, big.colour)];
      if (n < 100 || m > 0.2 * n) fail(`the cross-section through "${big.name}" fills ${n} pixels in its colour, ${m} without the filling`);
      ok(`the cross-section through "${big.name}" fills its cut: exact-colour pixels ${n} -> ${m} without the filling`);
      if (shotDir) {
        await page.check("#tmv-cap");
        await snapshot("objectsSection");
        await shot("viewer-objects-section.png");
      }
      await page.check("#tmv-cap");
      await setClip(500);
      await page.uncheck("#tmv-clip");
      for (const l of faults) await page.locator(`input[data-layer="${l.name}"]`).check();
    }
    for (const l of others) await page.locator(`input[data-layer="${l.name}"]`).check();
    const sheetsBack = await snapshot("sheetsBack");
    if (await changed(viewBase, sheetsBack) > 0.001) fail("showing the layers again did not restore the picture");
    ok("showing every layer again restores the picture");
  }

  if (problems.length) fail(`console or page problems: ${problems.join(" | ")}`);
  ok("no console error or warning, no page error, no failed request");
} catch (e) {
  if (!process.exitCode) {
    console.error(`FAIL ${e.stack || e}`);
    process.exitCode = 1;
  }
} finally {
  await browser.close();
}
