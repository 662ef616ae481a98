// The 3D viewer of terramesh's report.html (WebGL 2, no dependencies). It reads the scene
// from <script id="tmv-data"> (written by terramesh_io::viewer::Scene::to_json) and builds
// its controls inside <div id="tmv">: a toggle per layer, colour by field, vertical
// exaggeration, a cross-section plane (closed layers, the geological units, get their cut
// faces filled in their colour: stencil capping), and a readout of the point under the cursor.
(function () {
  "use strict";
  var root = document.getElementById("tmv");
  var dataEl = document.getElementById("tmv-data");
  if (!root || !dataEl) return;
  var scene = JSON.parse(dataEl.textContent);
  var origin = scene.origin;

  function el(tag, attrs, parent, text) {
    var e = document.createElement(tag);
    for (var k in attrs) e.setAttribute(k, attrs[k]);
    if (text !== undefined) e.textContent = text;
    if (parent) parent.appendChild(e);
    return e;
  }
  function bytes(s) {
    var bin = atob(s), u = new Uint8Array(bin.length);
    for (var i = 0; i < bin.length; i++) u[i] = bin.charCodeAt(i);
    return u.buffer;
  }
  function say(msg) {
    var p = el("p", { "class": "tmv-msg" }, root, msg);
    return p;
  }

  // ---------------------------------------------------------------- controls
  var bar = el("div", { "class": "tmv-bar" }, root);
  var layerBox = el("span", { "class": "tmv-group" }, bar);
  el("b", {}, layerBox, "Layers ");
  var layerInputs = scene.layers.map(function (l, i) {
    var lab = el("label", {}, layerBox);
    var cb = el("input", { type: "checkbox", id: "tmv-layer-" + i, "data-layer": l.name }, lab);
    cb.checked = l.visible;
    lab.appendChild(document.createTextNode(" " + l.name));
    return cb;
  });
  var fieldKeys = Object.keys(scene.fields);
  var g2 = el("span", { "class": "tmv-group" }, bar);
  el("label", { "for": "tmv-field" }, g2, "Colour by ");
  var fieldSel = el("select", { id: "tmv-field" }, g2);
  fieldKeys.forEach(function (k) {
    el("option", { value: k }, fieldSel, scene.fields[k].label);
  });
  var g3 = el("span", { "class": "tmv-group" }, bar);
  el("label", { "for": "tmv-exag" }, g3, "Vertical exaggeration ");
  var exagIn = el("input", { id: "tmv-exag", type: "range", min: "1", max: "20", step: "0.5", value: "1" }, g3);
  var exagOut = el("output", { "for": "tmv-exag" }, g3, "1x");
  var g4 = el("span", { "class": "tmv-group" }, bar);
  var clipLab = el("label", {}, g4);
  var clipCb = el("input", { id: "tmv-clip", type: "checkbox" }, clipLab);
  clipLab.appendChild(document.createTextNode(" Cross-section "));
  var clipAxis = el("select", { id: "tmv-clip-axis", "aria-label": "cross-section plane" }, g4);
  el("option", { value: "0" }, clipAxis, "north-south plane");
  el("option", { value: "1" }, clipAxis, "east-west plane");
  var clipPos = el("input", { id: "tmv-clip-pos", type: "range", min: "0", max: "1000", value: "500", "aria-label": "cross-section position" }, g4);
  var anyClosed = scene.layers.some(function (l) { return l.closed; });
  var capLab = el("label", {}, g4);
  var capCb = el("input", { id: "tmv-cap", type: "checkbox" }, capLab);
  capCb.checked = true;
  capLab.appendChild(document.createTextNode(" fill cut units"));
  if (!anyClosed) capLab.style.display = "none";
  var resetBtn = el("button", { id: "tmv-reset", type: "button" }, bar, "Reset view");

  var wrap = el("div", { "class": "tmv-wrap" }, root);
  var canvas = el("canvas", { id: "tmv-canvas", tabindex: "0", "aria-label": "3D view of the model" }, wrap);
  var legend = el("div", { "class": "tmv-legend", id: "tmv-legend" }, wrap);
  var readout = el("div", { "class": "tmv-readout", id: "tmv-readout" }, root,
    "Move the cursor over the surface for its coordinates and elevation.");
  el("p", { "class": "tmv-help" }, root,
    "Drag: orbit. Shift-drag or right-drag: pan. Wheel: zoom. The still pictures below are for printing.");
  if (scene.note) el("p", { "class": "tmv-note", id: "tmv-note" }, root, scene.note);

  var gl = canvas.getContext("webgl2", { antialias: true, preserveDrawingBuffer: true, stencil: true });
  if (!gl) {
    bar.style.display = "none";
    wrap.style.display = "none";
    readout.style.display = "none";
    say("This browser offers no WebGL 2, so the interactive view is off; the still pictures below show the same model.");
    return;
  }

  // ---------------------------------------------------------------- GL programs and buffers
  var VS = "#version 300 es\n" +
    "in vec3 a_pos; in float a_val; in vec3 a_col; uniform mat4 u_mvp; uniform float u_exag; uniform float u_psize;\n" +
    "out vec3 v_world; out float v_val; out vec3 v_col;\n" +
    "void main(){ vec3 p = vec3(a_pos.xy, a_pos.z * u_exag); v_world = p; v_val = a_val; v_col = a_col;\n" +
    "  gl_Position = u_mvp * vec4(p, 1.0); gl_PointSize = u_psize; }\n";
  var FS = "#version 300 es\nprecision highp float;\n" +
    "in vec3 v_world; in float v_val; in vec3 v_col; uniform sampler2D u_cmap; uniform vec2 u_range;\n" +
    "uniform int u_byField; uniform vec3 u_colour; uniform vec3 u_clip; uniform int u_clipOn;\n" +
    "uniform int u_points; uniform int u_vcol; uniform int u_cap; uniform vec3 u_light; out vec4 o;\n" +
    "void main(){\n" +
    "  if (u_cap == 1) { o = vec4(u_colour, 1.0); return; }\n" +
    "  if (u_clipOn == 1 && dot(u_clip.xy, v_world.xy) > u_clip.z) discard;\n" +
    "  float t = clamp((v_val - u_range.x) / (u_range.y - u_range.x), 0.0, 1.0);\n" +
    "  vec3 c = u_vcol == 1 ? v_col : u_byField == 1 ? texture(u_cmap, vec2(t * 255.0 / 256.0 + 0.5 / 256.0, 0.5)).rgb : u_colour;\n" +
    "  if (u_points == 1) { vec2 d = gl_PointCoord - 0.5; float r = dot(d, d);\n" +
    "    if (r > 0.25) discard; o = vec4(r > 0.12 ? vec3(0.1) : c, 1.0); return; }\n" +
    "  vec3 n = normalize(cross(dFdx(v_world), dFdy(v_world)));\n" +
    "  float s = 0.45 + 0.55 * max(dot(n, u_light), 0.0);\n" +
    "  if (!gl_FrontFacing) s *= 0.55;\n" +
    "  o = vec4(c * s, 1.0); }\n";
  function shader(type, src) {
    var s = gl.createShader(type);
    gl.shaderSource(s, src);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    return s;
  }
  var prog = gl.createProgram();
  gl.attachShader(prog, shader(gl.VERTEX_SHADER, VS));
  gl.attachShader(prog, shader(gl.FRAGMENT_SHADER, FS));
  gl.bindAttribLocation(prog, 0, "a_pos");
  gl.bindAttribLocation(prog, 1, "a_val");
  gl.bindAttribLocation(prog, 2, "a_col");
  gl.linkProgram(prog);
  if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(prog));
  var U = {};
  ["u_mvp", "u_exag", "u_psize", "u_cmap", "u_range", "u_byField", "u_colour", "u_clip",
    "u_clipOn", "u_points", "u_vcol", "u_cap", "u_light"].forEach(function (n) { U[n] = gl.getUniformLocation(prog, n); });

  // One 256 x 1 texture per field: its anchors interpolated linearly, as ColourMap::at does.
  var cmaps = {};
  fieldKeys.forEach(function (k) {
    var a = scene.fields[k].colours, px = new Uint8Array(256 * 4);
    for (var i = 0; i < 256; i++) {
      var t = (i / 255) * (a.length - 1), j = Math.min(Math.floor(t), a.length - 2), f = t - j;
      for (var c = 0; c < 3; c++) px[4 * i + c] = Math.round(a[j][c] + (a[j + 1][c] - a[j][c]) * f);
      px[4 * i + 3] = 255;
    }
    var tex = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, tex);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 256, 1, 0, gl.RGBA, gl.UNSIGNED_BYTE, px);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
    cmaps[k] = tex;
  });

  var lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  var layers = scene.layers.map(function (l) {
    var pos = new Float32Array(bytes(l.positions));
    var L = { name: l.name, kind: l.kind, pos: pos, n: l.vertices, colour: l.colour.map(function (c) { return c / 255; }),
      pickable: l.pickable, clipped: l.clipped, closed: l.closed, vcol: !!l.vertex_colours,
      fields: {}, vbufs: {}, count: 0 };
    for (var i = 0; i < pos.length; i += 3) {
      for (var k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], pos[i + k]); hi[k] = Math.max(hi[k], pos[i + k]); }
    }
    L.vao = gl.createVertexArray();
    gl.bindVertexArray(L.vao);
    var pb = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, pb);
    gl.bufferData(gl.ARRAY_BUFFER, pos, gl.STATIC_DRAW);
    gl.enableVertexAttribArray(0);
    gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 0, 0);
    if (l.vertex_colours) {
      var cb2 = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, cb2);
      gl.bufferData(gl.ARRAY_BUFFER, new Uint8Array(bytes(l.vertex_colours)), gl.STATIC_DRAW);
      gl.enableVertexAttribArray(2);
      gl.vertexAttribPointer(2, 3, gl.UNSIGNED_BYTE, true, 0, 0);
    }
    if (l.kind === "triangles") {
      L.idx = new Uint32Array(bytes(l.indices));
      var ib = gl.createBuffer();
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ib);
      gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, L.idx, gl.STATIC_DRAW);
      L.count = L.idx.length;
    } else {
      L.count = l.vertices;
    }
    Object.keys(l.fields).forEach(function (k) {
      var v = new Float32Array(bytes(l.fields[k]));
      L.fields[k] = v;
      var b = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, b);
      gl.bufferData(gl.ARRAY_BUFFER, v, gl.STATIC_DRAW);
      L.vbufs[k] = b;
    });
    gl.bindVertexArray(null);
    return L;
  });
  var radius = 0.5 * Math.max(hi[0] - lo[0], hi[1] - lo[1], 1e-3);
  // The cap: a rectangle in the cross-section plane over the scene's box, redrawn per layer.
  var capVao = gl.createVertexArray(), capBuf = gl.createBuffer();
  gl.bindVertexArray(capVao);
  gl.bindBuffer(gl.ARRAY_BUFFER, capBuf);
  gl.bufferData(gl.ARRAY_BUFFER, 12 * 4, gl.DYNAMIC_DRAW);
  gl.enableVertexAttribArray(0);
  gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 0, 0);
  gl.bindVertexArray(null);
  function capQuad(plane) {
    var m = 0.01 * radius, z0 = lo[2] - m, z1 = hi[2] + m, d = plane[2];
    var q = plane[0] === 1
      ? [d, lo[1] - m, z0, d, hi[1] + m, z0, d, hi[1] + m, z1, d, lo[1] - m, z1]
      : [lo[0] - m, d, z0, hi[0] + m, d, z0, hi[0] + m, d, z1, lo[0] - m, d, z1];
    gl.bindBuffer(gl.ARRAY_BUFFER, capBuf);
    gl.bufferSubData(gl.ARRAY_BUFFER, 0, new Float32Array(q));
  }

  // ---------------------------------------------------------------- camera
  var FOV = 40 * Math.PI / 180;
  var cam = {};
  function resetCamera() {
    cam.yaw = -0.55; cam.pitch = 0.7;
    cam.dist = 4 * Math.max(radius, 0.6 * (hi[2] - lo[2]) * exag());
    cam.tx = 0.5 * (lo[0] + hi[0]); cam.ty = 0.5 * (lo[1] + hi[1]);
  }
  function exag() { return parseFloat(exagIn.value); }
  resetCamera();
  function basis() {
    var e = exag(), cp = Math.cos(cam.pitch);
    var t = [cam.tx, cam.ty, 0.5 * (lo[2] + hi[2]) * e];
    var d = [-Math.sin(cam.yaw) * cp, -Math.cos(cam.yaw) * cp, Math.sin(cam.pitch)];
    var eye = [t[0] + cam.dist * d[0], t[1] + cam.dist * d[1], t[2] + cam.dist * d[2]];
    var f = [-d[0], -d[1], -d[2]];
    var r = norm(cross(f, [0, 0, 1]));
    if (!isFinite(r[0])) r = [1, 0, 0];
    return { eye: eye, target: t, f: f, r: r, u: cross(r, f) };
  }
  function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
  function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  function norm(a) { var l = Math.sqrt(dot(a, a)); return [a[0] / l, a[1] / l, a[2] / l]; }
  function matrix(b, aspect) {
    var near = cam.dist / 200, far = cam.dist * 4 + radius * 8 * exag();
    var ft = 1 / Math.tan(FOV / 2);
    // view (rows r, u, -f) then perspective, column-major for WebGL.
    var V = [b.r, b.u, [-b.f[0], -b.f[1], -b.f[2]]];
    var tr = V.map(function (row) { return -dot(row, b.eye); });
    var P00 = ft / aspect, P11 = ft, P22 = (far + near) / (near - far), P23 = 2 * far * near / (near - far);
    var m = new Float32Array(16);
    for (var c = 0; c < 3; c++) {
      m[4 * c] = P00 * V[0][c]; m[4 * c + 1] = P11 * V[1][c];
      m[4 * c + 2] = P22 * V[2][c]; m[4 * c + 3] = -V[2][c];
    }
    m[12] = P00 * tr[0]; m[13] = P11 * tr[1]; m[14] = P22 * tr[2] + P23; m[15] = -tr[2];
    return m;
  }

  // ---------------------------------------------------------------- drawing
  var frames = 0, pending = false;
  var light = norm([-1, 1, Math.SQRT2]);
  function clipPlane() {
    var axis = parseInt(clipAxis.value, 10), f = parseInt(clipPos.value, 10) / 1000;
    var d = lo[axis] + f * (hi[axis] - lo[axis]);
    return axis === 0 ? [1, 0, d] : [0, 1, d];
  }
  function legendUpdate() {
    var k = fieldSel.value, f = scene.fields[k];
    if (!f) { legend.style.display = "none"; return; }
    var stops = f.colours.map(function (c, i) {
      return "rgb(" + c.join(",") + ") " + (100 * i / (f.colours.length - 1)).toFixed(1) + "%";
    });
    legend.textContent = "";
    var g = el("div", { "class": "tmv-ramp" }, legend);
    g.style.background = "linear-gradient(to right," + stops.join(",") + ")";
    el("span", {}, legend, fmt(f.lo) + " " + f.unit);
    el("span", { "class": "tmv-mid" }, legend, f.label);
    el("span", {}, legend, fmt(f.hi) + " " + f.unit);
  }
  function fmt(v) { return Math.abs(v) >= 100 ? v.toFixed(1) : v.toFixed(2); }
  function draw() {
    pending = false;
    var dpr = window.devicePixelRatio || 1;
    var w = Math.max(1, Math.round(canvas.clientWidth * dpr)), h = Math.max(1, Math.round(canvas.clientHeight * dpr));
    if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
    gl.viewport(0, 0, w, h);
    gl.clearColor(0.93, 0.95, 0.97, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    gl.useProgram(prog);
    gl.uniformMatrix4fv(U.u_mvp, false, matrix(basis(), w / h));
    gl.uniform1f(U.u_exag, exag());
    gl.uniform1f(U.u_psize, Math.max(3, 4 * dpr));
    gl.uniform3fv(U.u_light, light);
    gl.uniform3fv(U.u_clip, clipPlane());
    gl.uniform1i(U.u_cmap, 0);
    gl.activeTexture(gl.TEXTURE0);
    var want = fieldSel.value;
    layers.forEach(function (L, i) {
      if (!layerInputs[i].checked || L.count === 0) return;
      var k = L.fields[want] ? want : Object.keys(L.fields)[0];
      gl.bindVertexArray(L.vao);
      if (k) {
        gl.bindBuffer(gl.ARRAY_BUFFER, L.vbufs[k]);
        gl.enableVertexAttribArray(1);
        gl.vertexAttribPointer(1, 1, gl.FLOAT, false, 0, 0);
        gl.bindTexture(gl.TEXTURE_2D, cmaps[k]);
        gl.uniform2f(U.u_range, scene.fields[k].lo, scene.fields[k].hi);
      } else {
        gl.disableVertexAttribArray(1);
        gl.vertexAttrib1f(1, 0);
        gl.uniform2f(U.u_range, 0, 1);
      }
      gl.uniform1i(U.u_byField, k ? 1 : 0);
      gl.uniform3fv(U.u_colour, L.colour);
      gl.uniform1i(U.u_clipOn, clipCb.checked && L.clipped ? 1 : 0);
      gl.uniform1i(U.u_points, L.kind === "points" ? 1 : 0);
      gl.uniform1i(U.u_vcol, L.vcol ? 1 : 0);
      gl.uniform1i(U.u_cap, 0);
      if (L.kind === "points") gl.drawArrays(gl.POINTS, 0, L.count);
      else gl.drawElements(gl.TRIANGLES, L.count, gl.UNSIGNED_INT, 0);
    });
    if (clipCb.checked && capCb.checked) drawCaps();
    gl.bindVertexArray(null);
    frames += 1;
    root.setAttribute("data-frames", String(frames));
    root.setAttribute("data-ready", "1");
  }
  // Stencil capping: for each shown closed layer, its clipped triangles count into the stencil
  // buffer (+1 back faces, -1 front faces, no depth test): along a pixel's ray, the part of a
  // closed surface on the kept side of the plane leaves a non-zero count exactly where the
  // plane lies inside the body. The plane's rectangle is then drawn there, depth-tested, in
  // the layer's colour, unshaded: the cut face filled.
  function drawCaps() {
    var plane = clipPlane();
    capQuad(plane);
    gl.uniform1i(U.u_byField, 0);
    gl.uniform1i(U.u_points, 0);
    gl.uniform1i(U.u_vcol, 0);
    gl.enable(gl.STENCIL_TEST);
    layers.forEach(function (L, i) {
      if (!L.closed || !L.clipped || !layerInputs[i].checked || L.kind !== "triangles") return;
      gl.clear(gl.STENCIL_BUFFER_BIT);
      gl.colorMask(false, false, false, false);
      gl.depthMask(false);
      gl.disable(gl.DEPTH_TEST);
      gl.stencilFunc(gl.ALWAYS, 0, 0xff);
      gl.stencilOpSeparate(gl.FRONT, gl.KEEP, gl.KEEP, gl.DECR_WRAP);
      gl.stencilOpSeparate(gl.BACK, gl.KEEP, gl.KEEP, gl.INCR_WRAP);
      gl.uniform1i(U.u_cap, 0);
      gl.uniform1i(U.u_clipOn, 1);
      gl.bindVertexArray(L.vao);
      gl.drawElements(gl.TRIANGLES, L.count, gl.UNSIGNED_INT, 0);
      gl.colorMask(true, true, true, true);
      gl.depthMask(true);
      gl.enable(gl.DEPTH_TEST);
      gl.stencilFunc(gl.NOTEQUAL, 0, 0xff);
      gl.stencilOp(gl.KEEP, gl.KEEP, gl.KEEP);
      gl.uniform1i(U.u_cap, 1);
      gl.uniform1i(U.u_clipOn, 0);
      gl.uniform3fv(U.u_colour, L.colour);
      gl.bindVertexArray(capVao);
      gl.drawArrays(gl.TRIANGLE_FAN, 0, 4);
    });
    gl.disable(gl.STENCIL_TEST);
    gl.uniform1i(U.u_cap, 0);
  }
  function redraw() {
    if (!pending) { pending = true; requestAnimationFrame(draw); }
  }

  // ---------------------------------------------------------------- cursor readout
  // A ray through the pixel, intersected with every triangle of the pickable layers (Moller-
  // Trumbore), in the exaggerated frame the picture shows; the nearest hit is reported.
  function pick(px, py) {
    var b = basis(), e = exag(), th = Math.tan(FOV / 2);
    var aspect = canvas.clientWidth / canvas.clientHeight;
    var x = (2 * px / canvas.clientWidth - 1) * th * aspect, y = (1 - 2 * py / canvas.clientHeight) * th;
    var d = [b.f[0] + x * b.r[0] + y * b.u[0], b.f[1] + x * b.r[1] + y * b.u[1], b.f[2] + x * b.r[2] + y * b.u[2]];
    var o = b.eye, best = null, clip = clipPlane();
    layers.forEach(function (L, li) {
      if (!L.pickable || !layerInputs[li].checked || L.kind !== "triangles") return;
      var P = L.pos, I = L.idx, clipOn = clipCb.checked && L.clipped;
      for (var t = 0; t < I.length; t += 3) {
        var a = 3 * I[t], bb = 3 * I[t + 1], c = 3 * I[t + 2];
        var ax = P[a], ay = P[a + 1], az = P[a + 2] * e;
        var e1x = P[bb] - ax, e1y = P[bb + 1] - ay, e1z = P[bb + 2] * e - az;
        var e2x = P[c] - ax, e2y = P[c + 1] - ay, e2z = P[c + 2] * e - az;
        var hx = d[1] * e2z - d[2] * e2y, hy = d[2] * e2x - d[0] * e2z, hz = d[0] * e2y - d[1] * e2x;
        var det = e1x * hx + e1y * hy + e1z * hz;
        if (Math.abs(det) < 1e-12) continue;
        var inv = 1 / det, sx = o[0] - ax, sy = o[1] - ay, sz = o[2] - az;
        var u = (sx * hx + sy * hy + sz * hz) * inv;
        if (u < 0 || u > 1) continue;
        var qx = sy * e1z - sz * e1y, qy = sz * e1x - sx * e1z, qz = sx * e1y - sy * e1x;
        var v = (d[0] * qx + d[1] * qy + d[2] * qz) * inv;
        if (v < 0 || u + v > 1) continue;
        var dist = (e2x * qx + e2y * qy + e2z * qz) * inv;
        if (dist <= 0 || (best && dist >= best.dist)) continue;
        var hxw = o[0] + dist * d[0], hyw = o[1] + dist * d[1];
        if (clipOn && clip[0] * hxw + clip[1] * hyw > clip[2]) continue;
        best = { dist: dist, layer: L, tri: [I[t], I[t + 1], I[t + 2]], w: [1 - u - v, u, v] };
      }
    });
    return best;
  }
  function at(values, hit) {
    return hit.w[0] * values[hit.tri[0]] + hit.w[1] * values[hit.tri[1]] + hit.w[2] * values[hit.tri[2]];
  }
  var mouse = null, pickPending = false;
  function showPick() {
    pickPending = false;
    if (!mouse) return;
    var hit = pick(mouse[0], mouse[1]);
    if (!hit) {
      readout.textContent = "The cursor is not over the surface.";
      readout.removeAttribute("data-easting");
      return;
    }
    var P = hit.layer.pos, c = [0, 1, 2].map(function (k) {
      return hit.w[0] * P[3 * hit.tri[0] + k] + hit.w[1] * P[3 * hit.tri[1] + k] + hit.w[2] * P[3 * hit.tri[2] + k] + origin[k];
    });
    var parts = ["E " + c[0].toFixed(2) + " m, N " + c[1].toFixed(2) + " m (" + scene.crs + ")",
      "elevation " + c[2].toFixed(2) + " m" + (scene.heights ? " " + scene.heights : "")];
    Object.keys(hit.layer.fields).forEach(function (k) {
      if (k === "elevation") return;
      parts.push(scene.fields[k].label + " " + at(hit.layer.fields[k], hit).toFixed(3) + " " + scene.fields[k].unit);
    });
    readout.textContent = hit.layer.name + ": " + parts.join("; ");
    readout.setAttribute("data-easting", c[0].toFixed(3));
    readout.setAttribute("data-northing", c[1].toFixed(3));
    readout.setAttribute("data-elevation", c[2].toFixed(3));
  }

  // ---------------------------------------------------------------- interaction
  var drag = null;
  canvas.addEventListener("contextmenu", function (ev) { ev.preventDefault(); });
  canvas.addEventListener("pointerdown", function (ev) {
    drag = { x: ev.clientX, y: ev.clientY, pan: ev.button === 2 || ev.shiftKey };
    if (canvas.setPointerCapture) canvas.setPointerCapture(ev.pointerId);
  });
  canvas.addEventListener("pointerup", function () { drag = null; });
  canvas.addEventListener("pointercancel", function () { drag = null; });
  canvas.addEventListener("pointermove", function (ev) {
    var rect = canvas.getBoundingClientRect();
    mouse = [ev.clientX - rect.left, ev.clientY - rect.top];
    if (drag) {
      var dx = ev.clientX - drag.x, dy = ev.clientY - drag.y;
      drag.x = ev.clientX; drag.y = ev.clientY;
      if (drag.pan) {
        var b = basis(), s = 2 * cam.dist * Math.tan(FOV / 2) / canvas.clientHeight;
        var fw = norm([b.f[0], b.f[1], 0]);
        if (!isFinite(fw[0])) fw = [b.u[0], b.u[1], 0];
        cam.tx += -dx * s * b.r[0] + dy * s * fw[0];
        cam.ty += -dx * s * b.r[1] + dy * s * fw[1];
      } else {
        cam.yaw -= dx * 0.008;
        cam.pitch = Math.max(-1.2, Math.min(1.55, cam.pitch + dy * 0.008));
      }
      redraw();
    }
    if (!pickPending) { pickPending = true; requestAnimationFrame(showPick); }
  });
  canvas.addEventListener("wheel", function (ev) {
    ev.preventDefault();
    cam.dist = Math.max(radius * 0.02, Math.min(radius * 20, cam.dist * Math.exp(ev.deltaY * 0.0015)));
    redraw();
  }, { passive: false });
  layerInputs.forEach(function (cb) { cb.addEventListener("change", redraw); });
  fieldSel.addEventListener("change", function () { legendUpdate(); redraw(); });
  exagIn.addEventListener("input", function () { exagOut.textContent = exag() + "x"; redraw(); });
  [clipCb, clipAxis, clipPos, capCb].forEach(function (c) { c.addEventListener("input", redraw); c.addEventListener("change", redraw); });
  resetBtn.addEventListener("click", function () { resetCamera(); redraw(); });
  window.addEventListener("resize", redraw);
  canvas.addEventListener("webglcontextlost", function (ev) {
    ev.preventDefault();
    say("The 3D view lost its WebGL context; reload the page to see it again.");
  });
  legendUpdate();
  redraw();
})();
