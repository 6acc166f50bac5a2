// barhinge fold-path viewer: WebGL2 sheet, 2-D crease pattern, charts. No network, no library.
// Data: the JSON of #bh-data (the mesh, the run) and one base64 block per state and array
// (#bh-X<s> positions, #bh-F<s> fold angles, #bh-M<s> moments, #bh-E<s> energies), decoded
// when a state is first shown. Arrays are little-endian typed arrays.
"use strict";
window.addEventListener("error", (e) => {  // say it on the page too, not only in the console
  const m = document.getElementById("msg");
  if (m) m.textContent = `viewer error: ${e.message}`;
});
(function () {
  const T0 = performance.now(), timing = {};
  const D = JSON.parse(document.getElementById("bh-data").textContent);
  timing.parse = performance.now() - T0;
  function dec(s, T) {
    if (Uint8Array.fromBase64) return new T(Uint8Array.fromBase64(s).buffer);
    const b = atob(s), u = new Uint8Array(b.length);
    for (let i = 0; i < b.length; i++) u[i] = b.charCodeAt(i);
    return new T(u.buffer);
  }
  const S = D.n_states, N = D.n_nodes, QP = D.positions;
  // positions: float32, or uint16 on a grid (lo + q * step) whose half step bounds the error
  const EPS = QP.dtype === "uint16" ? 0.5 * Math.hypot(...QP.step) : 0;
  const blocks = new Map();
  function block(k, s, decode) {
    const key = `${k}${s}`;
    if (!blocks.has(key)) blocks.set(key, decode(document.getElementById(`bh-${key}`).textContent));
    return blocks.get(key);
  }
  function pos(s) {  // (N*3) float32 positions of state s
    return block("X", s, (t) => {
      if (QP.dtype !== "uint16") return dec(t, Float32Array);
      const q = dec(t, Uint16Array), P = new Float32Array(3 * N), lo = QP.lo, st = QP.step;
      for (let i = 0; i < 3 * N; i += 3) {
        P[i] = lo[0] + q[i] * st[0]; P[i + 1] = lo[1] + q[i + 1] * st[1]; P[i + 2] = lo[2] + q[i + 2] * st[2];
      }
      return P;
    });
  }
  const foldOf = (s) => block("F", s, (t) => Float32Array.from(dec(t, Int16Array), (q) => q / 100));  // deg
  const HAS_M = D.blocks.includes("M"), HAS_E = D.blocks.includes("E");
  const momOf = (s) => block("M", s, (t) => dec(t, Float32Array));
  const TRI = dec(D.triangles, Uint32Array);      // T*3
  const BARS = dec(D.bars, Uint32Array);          // B*2
  const L0 = dec(D.bar_L0, Float32Array);
  const CR = dec(D.creases, Uint32Array);         // E*2
  const FLAT = dec(D.flat, Float32Array);         // Nv*2
  const FIXED = D.fixed ? dec(D.fixed, Uint8Array) : null;  // N*3
  const LOADS = D.loads ? dec(D.loads, Float32Array) : null;
  const ACT = new Set(D.actuators);
  const ASSIGN = D.assignment;
  const T = TRI.length / 3, B = BARS.length / 2, E = CR.length / 2;
  timing.decode = performance.now() - T0;

  // ---------------------------------------------------------------- fields from positions
  const boundary = new Uint8Array(N);
  (function () {
    const count = new Map();
    for (let t = 0; t < T; t++) for (let c = 0; c < 3; c++) {
      const a = TRI[3 * t + c], b = TRI[3 * t + (c + 1) % 3];
      const k = a < b ? a * N + b : b * N + a;
      count.set(k, (count.get(k) || 0) + 1);
    }
    for (const [k, n] of count) if (n === 1) { boundary[Math.floor(k / N)] = 1; boundary[k % N] = 1; }
  })();
  const used = new Uint8Array(N);
  for (let i = 0; i < TRI.length; i++) used[TRI[i]] = 1;

  function barStrainNodes(s) {  // mean engineering strain (L - L0)/L0 of the bars at each node
    const P = pos(s), sum = new Float64Array(N), cnt = new Float64Array(N);
    for (let b = 0; b < B; b++) {
      const i = BARS[2 * b], j = BARS[2 * b + 1];
      const dx = P[3 * j] - P[3 * i], dy = P[3 * j + 1] - P[3 * i + 1], dz = P[3 * j + 2] - P[3 * i + 2];
      const dL = Math.hypot(dx, dy, dz) - L0[b];
      const e = Math.abs(dL) <= 2 * EPS ? 0 : dL / L0[b];  // below the stored positions' resolution: 0
      sum[i] += e; sum[j] += e; cnt[i]++; cnt[j]++;
    }
    const out = new Float64Array(N);
    for (let i = 0; i < N; i++) out[i] = cnt[i] ? sum[i] / cnt[i] : NaN;
    return out;
  }
  function displacement(s) {
    const P = pos(s), P0 = pos(0), out = new Float64Array(N);
    for (let i = 0; i < N; i++)
      out[i] = Math.hypot(P[3 * i] - P0[3 * i], P[3 * i + 1] - P0[3 * i + 1], P[3 * i + 2] - P0[3 * i + 2]);
    return out;
  }
  function gaussian(s) {  // angle defect / mixed Voronoi area (Meyer et al. 2003), NaN at the boundary
    // with 16-bit positions a corner angle is known to 2 EPS (1/|a| + 1/|b|) (first order in
    // the position error EPS of each end): a node's defect within the sum of these is 0
    const P = pos(s), ang = new Float64Array(N), area = new Float64Array(N), err = new Float64Array(N);
    const v = (a, b) => [P[3 * b] - P[3 * a], P[3 * b + 1] - P[3 * a + 1], P[3 * b + 2] - P[3 * a + 2]];
    const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    const cr = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    for (let t = 0; t < T; t++) {
      const id = [TRI[3 * t], TRI[3 * t + 1], TRI[3 * t + 2]], A = [], L2 = [];
      for (let c = 0; c < 3; c++) {
        const p = id[c], q = id[(c + 1) % 3], r = id[(c + 2) % 3];
        const a = v(p, q), b = v(p, r), o = v(q, r);
        A.push(Math.atan2(Math.hypot(...cr(a, b)), dot(a, b)));
        if (EPS) err[p] += 2 * EPS * (1 / Math.sqrt(dot(a, a)) + 1 / Math.sqrt(dot(b, b)));
        L2.push(dot(o, o));  // squared length of the side opposite corner c
      }
      const e1 = v(id[0], id[1]), e2 = v(id[0], id[2]);
      const at = 0.5 * Math.hypot(...cr(e1, e2));
      const obt = A.map((x) => x > Math.PI / 2), anyObt = obt.some((x) => x);
      for (let c = 0; c < 3; c++) {
        ang[id[c]] += A[c];
        let a;
        if (anyObt) a = (obt[c] ? 0.5 : 0.25) * at;
        else {
          const c1 = (c + 1) % 3, c2 = (c + 2) % 3;
          const cot = (x) => 1 / Math.tan(Math.min(Math.max(x, 1e-12), Math.PI - 1e-12));
          a = (L2[c1] * cot(A[c1]) + L2[c2] * cot(A[c2])) / 8;
        }
        area[id[c]] += a;
      }
    }
    const out = new Float64Array(N);
    for (let i = 0; i < N; i++) {
      const d = 2 * Math.PI - ang[i];
      out[i] = boundary[i] || !used[i] ? NaN : Math.abs(d) <= err[i] ? 0 : d / area[i];
    }
    return out;
  }
  function foldNodes(s) {  // mean fold angle of the creases at each node (deg)
    const F = foldOf(s), sum = new Float64Array(N), cnt = new Float64Array(N), out = new Float64Array(N);
    for (let e = 0; e < E; e++) {
      const a = ASSIGN[e];
      if (a !== "M" && a !== "V" && a !== "U") continue;
      const f = F[e];
      for (const i of [CR[2 * e], CR[2 * e + 1]]) { sum[i] += f; cnt[i]++; }
    }
    for (let i = 0; i < N; i++) out[i] = cnt[i] ? sum[i] / cnt[i] : NaN;
    return out;
  }
  function energy(s) { return Float64Array.from(block("E", s, (t) => dec(t, Float32Array))); }

  const MODES = {
    fold: { label: "fold angle (deg): mountain red, valley blue", f: foldNodes, div: true, mv: true },
    strain: { label: "bar strain (mean at node)", f: barStrainNodes, div: true },
    displacement: { label: "displacement |u| from state 0", f: displacement, div: false },
    gaussian: { label: "Gaussian curvature (angle defect / area, 1/length\u00b2)", f: gaussian, div: true },
  };
  if (!E) delete MODES.fold;
  if (HAS_E) MODES.energy = { label: "energy density (energy / area)", f: energy, div: false };

  // colour range of a mode: over all states (fixed while playing), symmetric for diverging maps
  const ranges = {};
  function range(m) {
    if (ranges[m]) return ranges[m];
    let lo = Infinity, hi = -Infinity;
    const step = Math.max(1, Math.floor(S / 6)), states = [];
    for (let s = 0; s < S; s += step) states.push(s);
    if (states[states.length - 1] !== S - 1) states.push(S - 1);
    const scan = (v) => { for (const x of v) if (Number.isFinite(x)) { if (x < lo) lo = x; if (x > hi) hi = x; } };
    if (m === "fold") { lo = -D.fold_absmax; hi = D.fold_absmax; } else for (const s of states) scan(MODES[m].f(s));
    if (!Number.isFinite(lo)) { lo = 0; hi = 1; }
    if (MODES[m].div) { const a = Math.max(Math.abs(lo), Math.abs(hi)) || 1; lo = -a; hi = a; }
    if (hi <= lo) hi = lo + 1;
    return (ranges[m] = [lo, hi]);
  }
  // mountain (FOLD < 0) red, valley (FOLD > 0) blue; other diverging fields blue-white-red
  function cmap(m, t) {
    t = Math.min(Math.max(t, 0), 1);
    if (MODES[m].div) {
      const neg = MODES[m].mv ? [0.84, 0.15, 0.16] : [0.23, 0.30, 0.75];
      const pos = MODES[m].mv ? [0.13, 0.40, 0.80] : [0.71, 0.02, 0.15];
      const w = [0.94, 0.94, 0.92], u = Math.abs(2 * t - 1), c = t < 0.5 ? neg : pos;
      return [0, 1, 2].map((k) => w[k] + (c[k] - w[k]) * u);
    }
    const stops = [[0.27, 0.00, 0.33], [0.23, 0.32, 0.55], [0.13, 0.57, 0.55], [0.37, 0.79, 0.38], [0.99, 0.91, 0.14]];
    const x = t * (stops.length - 1), i = Math.min(Math.floor(x), stops.length - 2), f = x - i;
    return [0, 1, 2].map((k) => stops[i][k] + (stops[i + 1][k] - stops[i][k]) * f);
  }
  const MV = { M: [0.84, 0.15, 0.16], V: [0.13, 0.40, 0.80], B: [0.1, 0.1, 0.1], F: [0.6, 0.6, 0.6], U: [0.4, 0.4, 0.4], C: [0.6, 0.6, 0.6] };

  // ---------------------------------------------------------------- WebGL
  const cv = document.getElementById("gl");
  const gl = cv.getContext("webgl2", { antialias: true, preserveDrawingBuffer: true });
  if (!gl) { document.getElementById("msg").textContent = "This browser has no WebGL2: the 3-D view is off."; }
  function shader(type, src) {
    const s = gl.createShader(type); gl.shaderSource(s, src); gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    return s;
  }
  function program(vs, fs) {
    const p = gl.createProgram();
    gl.attachShader(p, shader(gl.VERTEX_SHADER, vs)); gl.attachShader(p, shader(gl.FRAGMENT_SHADER, fs));
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
    return p;
  }
  let meshP, lineP, vaoMesh, vaoLine, buf = {};
  const VS_MESH = `#version 300 es
  in vec3 p; in vec3 c; uniform mat4 M; out vec3 vp; out vec3 vc;
  void main(){ gl_Position = M * vec4(p,1.0); vp = p; vc = c; }`;
  const FS_MESH = `#version 300 es
  precision highp float; in vec3 vp; in vec3 vc; uniform vec3 L; out vec4 o;
  void main(){ vec3 n = normalize(cross(dFdx(vp), dFdy(vp)));  // flat shading: one normal per panel
    float d = abs(dot(n, L)); o = vec4(vc * (0.35 + 0.65 * d), 1.0); }`;
  const VS_LINE = `#version 300 es
  in vec3 p; in vec3 c; uniform mat4 M; uniform float ps; out vec3 vc;
  void main(){ gl_Position = M * vec4(p,1.0); gl_Position.z -= 0.002 * gl_Position.w; vc = c; gl_PointSize = ps; }`;
  const FS_LINE = `#version 300 es
  precision highp float; in vec3 vc; out vec4 o; void main(){ o = vec4(vc,1.0); }`;

  // crease segments + actuator/support/load markers, rebuilt per state
  const lineIdx = [];     // pairs of node ids of the creases drawn (M, V, U, B)
  for (let e = 0; e < E; e++) if (ASSIGN[e] !== "F" && ASSIGN[e] !== "C") lineIdx.push(e);
  const supp = [];
  if (FIXED) for (let i = 0; i < FIXED.length / 3; i++) if (FIXED[3 * i] || FIXED[3 * i + 1] || FIXED[3 * i + 2]) supp.push(i);
  const loadN = [];
  if (LOADS) for (let i = 0; i < LOADS.length / 3; i++) if (LOADS[3 * i] || LOADS[3 * i + 1] || LOADS[3 * i + 2]) loadN.push(i);
  let maxLoad = 0;
  for (const i of loadN) maxLoad = Math.max(maxLoad, Math.hypot(LOADS[3 * i], LOADS[3 * i + 1], LOADS[3 * i + 2]));

  // bounding box over all states: a fixed camera target and scale
  const [lo, hi] = D.box;
  const center = [0, 1, 2].map((k) => (lo[k] + hi[k]) / 2);
  const radius = 0.5 * Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 1;
  const cam = { yaw: -0.6, pitch: 0.75, dist: 2.0 * radius, target: center.slice() };

  function setup() {
    meshP = program(VS_MESH, FS_MESH); lineP = program(VS_LINE, FS_LINE);
    vaoMesh = gl.createVertexArray(); gl.bindVertexArray(vaoMesh);
    for (const name of ["p", "c"]) {
      buf[name] = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, buf[name]);
      gl.bufferData(gl.ARRAY_BUFFER, N * 12, gl.DYNAMIC_DRAW);
      const l = gl.getAttribLocation(meshP, name); gl.enableVertexAttribArray(l); gl.vertexAttribPointer(l, 3, gl.FLOAT, false, 0, 0);
    }
    buf.idx = gl.createBuffer(); gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, buf.idx);
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, TRI, gl.STATIC_DRAW);
    vaoLine = gl.createVertexArray(); gl.bindVertexArray(vaoLine);
    for (const name of ["lp", "lc"]) {
      buf[name] = gl.createBuffer(); gl.bindBuffer(gl.ARRAY_BUFFER, buf[name]);
      const l = gl.getAttribLocation(lineP, name === "lp" ? "p" : "c"); gl.enableVertexAttribArray(l); gl.vertexAttribPointer(l, 3, gl.FLOAT, false, 0, 0);
    }
    gl.bindVertexArray(null);
    gl.enable(gl.DEPTH_TEST);
  }

  // ---------------------------------------------------------------- state
  const V = { state: 0, mode: "fold", hover: -1, ready: false, values: null };
  const luts = {};
  function lut(m) {  // 256 colours of a mode's map
    if (!luts[m]) { luts[m] = new Float32Array(768); for (let j = 0; j < 256; j++) luts[m].set(cmap(m, j / 255), 3 * j); }
    return luts[m];
  }
  const cbuf = new Float32Array(3 * N);
  function colours(s) {
    const c = cbuf;
    if (V.mode === "fold") {  // fold angles live on the creases (coloured lines): panels stay paper-coloured
      for (let i = 0; i < 3 * N; i += 3) { c[i] = 0.93; c[i + 1] = 0.92; c[i + 2] = 0.88; }
      return c;
    }
    const vals = MODES[V.mode].f(s), [a, b] = range(V.mode), L = lut(V.mode);
    for (let i = 0; i < N; i++) {
      const x = vals[i];
      if (!Number.isFinite(x)) { c[3 * i] = c[3 * i + 1] = c[3 * i + 2] = 0.75; continue; }
      const j = 3 * Math.round(255 * Math.min(Math.max((x - a) / (b - a), 0), 1));
      c[3 * i] = L[j]; c[3 * i + 1] = L[j + 1]; c[3 * i + 2] = L[j + 2];
    }
    return c;
  }
  const LINE_COL = new Float32Array(3 * E);  // each crease's colour outside the fold mode
  for (let e = 0; e < E; e++) LINE_COL.set(ACT.has(e) ? [0.1, 0.7, 0.2] : MV[ASSIGN[e]] || MV.U, 3 * e);
  const BY_ANGLE = Uint8Array.from({ length: E }, (_, e) => (ASSIGN[e] !== "B" && !ACT.has(e) ? 1 : 0));
  let lbuf = null;
  function lineData(P, s) {
    const n = 2 * lineIdx.length + 2 * loadN.length + supp.length;
    if (!lbuf || lbuf.n !== n) lbuf = { n, p: new Float32Array(3 * n), c: new Float32Array(3 * n) };
    const p = lbuf.p, c = lbuf.c;
    let k = 0;
    const put = (x, y, z, col) => { p[3 * k] = x; p[3 * k + 1] = y; p[3 * k + 2] = z; c[3 * k] = col[0]; c[3 * k + 1] = col[1]; c[3 * k + 2] = col[2]; k++; };
    const node = (i, col) => put(P[3 * i], P[3 * i + 1], P[3 * i + 2], col);
    const F = V.mode === "fold" ? foldOf(s) : null, amax = F ? range("fold")[1] : 1, L = F ? lut("fold") : null;
    for (let j = 0; j < lineIdx.length; j++) {  // plain loop: 10^5 creases per state
      const e = lineIdx[j], a = CR[2 * e], b = CR[2 * e + 1], q = 3 * k;
      let r = LINE_COL[3 * e], g = LINE_COL[3 * e + 1], bl = LINE_COL[3 * e + 2];
      if (F && BY_ANGLE[e]) {
        const f = F[e], t = 0.5 + 0.5 * Math.sign(f) * (0.35 + 0.65 * Math.min(1, Math.abs(f) / amax));
        const x = 3 * Math.round(255 * t); r = L[x]; g = L[x + 1]; bl = L[x + 2];
      }
      if (e === V.hover) { r = 1; g = 0.75; bl = 0; }
      p[q] = P[3 * a]; p[q + 1] = P[3 * a + 1]; p[q + 2] = P[3 * a + 2];
      p[q + 3] = P[3 * b]; p[q + 4] = P[3 * b + 1]; p[q + 5] = P[3 * b + 2];
      c[q] = c[q + 3] = r; c[q + 1] = c[q + 4] = g; c[q + 2] = c[q + 5] = bl;
      k += 2;
    }
    const nl = k, purple = [0.55, 0.1, 0.6];
    for (const i of loadN) {  // load arrows: a segment along the load, 0.15 radius long at the largest
      const f = 0.15 * radius / maxLoad;
      node(i, purple);
      put(P[3 * i] + f * LOADS[3 * i], P[3 * i + 1] + f * LOADS[3 * i + 1], P[3 * i + 2] + f * LOADS[3 * i + 2], purple);
    }
    const nLoad = k - nl;
    for (const i of supp) node(i, [0, 0, 0]);
    return { p, c, nl, nLoad, np: supp.length };
  }

  function matrix() {
    const w = cv.clientWidth || cv.width, h = cv.clientHeight || cv.height, asp = w / h;
    const cp = Math.cos(cam.pitch), eye = [
      cam.target[0] + cam.dist * cp * Math.cos(cam.yaw),
      cam.target[1] + cam.dist * cp * Math.sin(cam.yaw),
      cam.target[2] + cam.dist * Math.sin(cam.pitch)];
    const f = norm(sub(cam.target, eye)), r = norm(cross(f, [0, 0, 1])), u = cross(r, f);
    const near = cam.dist / 100, far = cam.dist + 4 * radius, fy = 1 / Math.tan(0.4);
    const view = [r[0], u[0], -f[0], 0, r[1], u[1], -f[1], 0, r[2], u[2], -f[2], 0,
      -dot3(r, eye), -dot3(u, eye), dot3(f, eye), 1];
    const proj = [fy / asp, 0, 0, 0, 0, fy, 0, 0, 0, 0, (far + near) / (near - far), -1, 0, 0, 2 * far * near / (near - far), 0];
    const m = new Float32Array(16);
    for (let i = 0; i < 4; i++) for (let j = 0; j < 4; j++) {
      let s = 0; for (let k = 0; k < 4; k++) s += proj[k * 4 + j] * view[i * 4 + k]; m[i * 4 + j] = s;
    }
    return { m, r, u, f };
  }
  function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
  function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
  function dot3(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  function norm(a) { const l = Math.hypot(...a) || 1; return [a[0] / l, a[1] / l, a[2] / l]; }

  let cols = null, lines = null;
  function update(recolour) {
    const P = pos(V.state);
    if (recolour || !cols) cols = colours(V.state);
    if (!gl) return;
    gl.bindBuffer(gl.ARRAY_BUFFER, buf.p); gl.bufferSubData(gl.ARRAY_BUFFER, 0, P);
    gl.bindBuffer(gl.ARRAY_BUFFER, buf.c); gl.bufferSubData(gl.ARRAY_BUFFER, 0, cols);
    if (!timing.upload) timing.colours = performance.now() - T0;
    lines = lineData(P, V.state);
    if (!timing.upload) timing.lines = performance.now() - T0;
    gl.bindBuffer(gl.ARRAY_BUFFER, buf.lp); gl.bufferData(gl.ARRAY_BUFFER, lines.p, gl.DYNAMIC_DRAW);
    gl.bindBuffer(gl.ARRAY_BUFFER, buf.lc); gl.bufferData(gl.ARRAY_BUFFER, lines.c, gl.DYNAMIC_DRAW);
    if (!timing.upload) timing.upload = performance.now() - T0;
    draw();
    if (!timing.draw) { gl.finish(); timing.draw = performance.now() - T0; }
  }
  function draw() {
    if (!gl) return;
    const w = cv.clientWidth, h = cv.clientHeight, dpr = window.devicePixelRatio || 1;
    if (cv.width !== Math.round(w * dpr) || cv.height !== Math.round(h * dpr)) { cv.width = Math.round(w * dpr); cv.height = Math.round(h * dpr); }
    gl.viewport(0, 0, cv.width, cv.height);
    gl.clearColor(1, 1, 1, 1); gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    const { m, f } = matrix();
    gl.useProgram(meshP); gl.bindVertexArray(vaoMesh);
    gl.uniformMatrix4fv(gl.getUniformLocation(meshP, "M"), false, m);
    const l = norm([-f[0] + 0.3, -f[1] + 0.2, -f[2] + 0.5]);
    gl.uniform3fv(gl.getUniformLocation(meshP, "L"), l);
    gl.drawElements(gl.TRIANGLES, TRI.length, gl.UNSIGNED_INT, 0);
    gl.useProgram(lineP); gl.bindVertexArray(vaoLine);
    gl.uniformMatrix4fv(gl.getUniformLocation(lineP, "M"), false, m);
    gl.uniform1f(gl.getUniformLocation(lineP, "ps"), 7 * dpr);
    gl.drawArrays(gl.LINES, 0, lines.nl + lines.nLoad);
    if (lines.np) gl.drawArrays(gl.POINTS, lines.nl + lines.nLoad, lines.np);
    gl.bindVertexArray(null);
    V.drawn = cv.width * cv.height;  // pixels of the last drawing (0 before layout)
  }

  // camera: left drag orbits, right drag or shift-drag pans, wheel zooms
  let drag = null;
  cv.addEventListener("contextmenu", (e) => e.preventDefault());
  cv.addEventListener("pointerdown", (e) => { drag = { x: e.clientX, y: e.clientY, pan: e.button === 2 || e.shiftKey }; cv.setPointerCapture(e.pointerId); });
  cv.addEventListener("pointerup", () => { drag = null; });
  cv.addEventListener("pointermove", (e) => {
    if (!drag) return;
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y; drag.x = e.clientX; drag.y = e.clientY;
    if (drag.pan) {
      const { r, u } = matrix(), k = cam.dist / (cv.clientHeight || 1);
      for (let i = 0; i < 3; i++) cam.target[i] += k * (-dx * r[i] + dy * u[i]);
    } else {
      cam.yaw -= 0.01 * dx; cam.pitch = Math.min(1.55, Math.max(-1.55, cam.pitch + 0.01 * dy));
    }
    draw();
  });
  cv.addEventListener("wheel", (e) => { e.preventDefault(); cam.dist *= Math.exp(0.001 * e.deltaY); draw(); }, { passive: false });

  // ---------------------------------------------------------------- 2-D crease pattern
  const cpc = document.getElementById("cp"), tip = document.getElementById("tip");
  let flo = [Infinity, Infinity], fhi = [-Infinity, -Infinity];
  for (let i = 0; i < FLAT.length; i += 2) for (let k = 0; k < 2; k++) { flo[k] = Math.min(flo[k], FLAT[i + k]); fhi[k] = Math.max(fhi[k], FLAT[i + k]); }
  function cpTransform() {
    const w = cpc.clientWidth, h = cpc.clientHeight, pad = 12;
    const s = Math.min((w - 2 * pad) / (fhi[0] - flo[0] || 1), (h - 2 * pad) / (fhi[1] - flo[1] || 1));
    const ox = (w - s * (fhi[0] - flo[0])) / 2, oy = (h - s * (fhi[1] - flo[1])) / 2;
    return (i) => [ox + s * (FLAT[2 * i] - flo[0]), h - oy - s * (FLAT[2 * i + 1] - flo[1])];
  }
  let cpBase = null;  // the pattern drawn once (one path per style); hover redraws one crease
  function strokeCrease(g, tr, e, hot) {
    const [x0, y0] = tr(CR[2 * e]), [x1, y1] = tr(CR[2 * e + 1]);
    g.moveTo(x0, y0); g.lineTo(x1, y1);
  }
  function rasterLines(img, tr, dpr, list, col) {  // DDA lines into RGBA pixels
    const px = img.data, W = img.width, H = img.height;
    const R = Math.round(255 * col[0]), G = Math.round(255 * col[1]), Bc = Math.round(255 * col[2]);
    for (const e of list) {
      const a = tr(CR[2 * e]), b = tr(CR[2 * e + 1]);
      const x0 = a[0] * dpr, y0 = a[1] * dpr, dx = b[0] * dpr - x0, dy = b[1] * dpr - y0;
      const n = Math.max(1, Math.ceil(Math.max(Math.abs(dx), Math.abs(dy))));
      for (let t = 0; t <= n; t++) {
        const x = Math.round(x0 + (dx * t) / n), y = Math.round(y0 + (dy * t) / n);
        if (x < 0 || y < 0 || x >= W || y >= H) continue;
        const i = 4 * (y * W + x);
        px[i] = R; px[i + 1] = G; px[i + 2] = Bc; px[i + 3] = 255;
      }
    }
  }
  function drawCP() {
    const dpr = window.devicePixelRatio || 1, w = cpc.clientWidth, h = cpc.clientHeight;
    const W = Math.round(w * dpr), H = Math.round(h * dpr);
    if (!W || !H) return;  // not laid out yet (a hidden or collapsed frame): drawn on resize
    const tr = cpTransform();
    if (!cpBase || cpBase.width !== W || cpBase.height !== H) {
      cpBase = document.createElement("canvas"); cpBase.width = W; cpBase.height = H;
      const g = cpBase.getContext("2d"); g.setTransform(dpr, 0, 0, dpr, 0, 0);
      const groups = new Map();
      for (let e = 0; e < E; e++) {
        const k = ACT.has(e) ? "act" : ASSIGN[e];
        if (!groups.has(k)) groups.set(k, []);
        groups.get(k).push(e);
      }
      // many creases: one pixel wide lines set straight into the image (a canvas strokes
      // 10^5 segments in seconds in a software renderer); actuators stroked on top
      const raster = E > 5000, img = raster ? g.createImageData(W, H) : null;
      for (const [k, list] of groups) {
        const col = k === "act" ? [0.1, 0.7, 0.2] : MV[k] || MV.U;
        if (raster && k !== "act") { rasterLines(img, tr, dpr, list, col); continue; }
        g.strokeStyle = `rgb(${col.map((x) => Math.round(255 * x)).join(",")})`;
        g.lineWidth = k === "act" ? 2.5 : 1.4;
        g.setLineDash(k === "M" ? [6, 3] : []);
        if (raster) continue;
        g.beginPath(); for (const e of list) strokeCrease(g, tr, e); g.stroke();
      }
      if (raster) {
        g.putImageData(img, 0, 0);
        const act = groups.get("act") || [];
        g.strokeStyle = "rgb(26,179,51)"; g.lineWidth = 2.5; g.setLineDash([]);
        g.beginPath(); for (const e of act) strokeCrease(g, tr, e); g.stroke();
      }
    }
    cpc.width = W; cpc.height = H;
    const g = cpc.getContext("2d"); g.drawImage(cpBase, 0, 0);
    if (V.hover >= 0) {
      g.setTransform(dpr, 0, 0, dpr, 0, 0); g.strokeStyle = "rgb(255,191,0)"; g.lineWidth = 4;
      g.beginPath(); strokeCrease(g, tr, V.hover); g.stroke();
    }
  }
  function nearestCrease(mx, my) {
    const tr = cpTransform(); let best = -1, bd = 8;
    for (let e = 0; e < E; e++) {
      const [x0, y0] = tr(CR[2 * e]), [x1, y1] = tr(CR[2 * e + 1]);
      const dx = x1 - x0, dy = y1 - y0, L = dx * dx + dy * dy || 1;
      const t = Math.min(1, Math.max(0, ((mx - x0) * dx + (my - y0) * dy) / L));
      const d = Math.hypot(mx - x0 - t * dx, my - y0 - t * dy);
      if (d < bd) { bd = d; best = e; }
    }
    return best;
  }
  function fmt(x, d) { if (Number.isInteger(x)) return String(x); return Number.isFinite(x) ? (Math.abs(x) >= 1e4 || (Math.abs(x) < 1e-3 && x !== 0) ? x.toExponential(d - 1) : x.toPrecision(d)) : "\u2013"; }
  const NAMES = { M: "mountain", V: "valley", B: "boundary", F: "flat", U: "unassigned", C: "cut" };
  function tipText(e) {
    const s = V.state, f = foldOf(s)[e], m = HAS_M ? momOf(s)[e] : NaN;
    return `crease ${e}${ACT.has(e) ? " (actuator)" : ""}\nassignment ${ASSIGN[e]} (${NAMES[ASSIGN[e]] || "?"})\nfold angle ${f.toFixed(2)}\u00b0\nmoment ${fmt(m, 4)}`;
  }
  function hover(e) {
    V.hover = e;
    if (e < 0) tip.style.display = "none";
    else { tip.textContent = tipText(e); tip.style.display = "block"; }
    drawCP(); update(false);
  }
  cpc.addEventListener("mousemove", (ev) => {
    const r = cpc.getBoundingClientRect(), mx = ev.clientX - r.left, my = ev.clientY - r.top;
    const e = nearestCrease(mx, my);
    if (e !== V.hover) hover(e);
    tip.style.left = `${ev.clientX + 14}px`; tip.style.top = `${ev.clientY + 10}px`;
  });
  cpc.addEventListener("mouseleave", () => hover(-1));

  // ---------------------------------------------------------------- colour bar, charts
  function niceTicks(a, b, n) {
    const span = b - a, raw = span / n, p = Math.pow(10, Math.floor(Math.log10(raw)));
    const step = [1, 2, 2.5, 5, 10].map((k) => k * p).find((k) => span / k <= n) || 10 * p;
    const out = []; for (let x = Math.ceil(a / step) * step; x <= b + 1e-9 * span; x += step) out.push(Math.abs(x) < 1e-12 * span ? 0 : x);
    return out;
  }
  function tickLabel(x) { return Math.abs(x) >= 1e4 || (Math.abs(x) < 1e-2 && x !== 0) ? x.toExponential(1) : String(+x.toPrecision(6)); }
  function drawBar() {
    const c = document.getElementById("bar"), dpr = window.devicePixelRatio || 1, w = c.clientWidth, h = c.clientHeight;
    c.width = w * dpr; c.height = h * dpr;
    const g = c.getContext("2d"); g.setTransform(dpr, 0, 0, dpr, 0, 0); g.clearRect(0, 0, w, h);
    const [a, b] = range(V.mode), x0 = 10, x1 = w - 10;
    for (let x = x0; x < x1; x++) { const k = cmap(V.mode, (x - x0) / (x1 - x0)); g.fillStyle = `rgb(${k.map((v) => Math.round(255 * v)).join(",")})`; g.fillRect(x, 18, 1, 12); }
    g.fillStyle = "#222"; g.font = "11px sans-serif"; g.textAlign = "center";
    g.fillText(MODES[V.mode].label, w / 2, 12);
    for (const t of niceTicks(a, b, 6)) { const x = x0 + (t - a) / (b - a) * (x1 - x0); g.fillRect(x, 30, 1, 4); g.fillText(tickLabel(t), x, 45); }
  }
  const PALETTE = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f"];
  const SER = {}; for (const k in D.series) SER[k] = dec(D.series[k], Float64Array);
  const xKey = D.x_key;
  function chart(c, title, keys) {
    const dpr = window.devicePixelRatio || 1, w = c.clientWidth, h = c.clientHeight;
    c.width = w * dpr; c.height = h * dpr;
    const g = c.getContext("2d"); g.setTransform(dpr, 0, 0, dpr, 0, 0); g.clearRect(0, 0, w, h);
    const xs = SER[xKey]; let ya = Infinity, yb = -Infinity;
    for (const k of keys) for (const y of SER[k]) if (Number.isFinite(y)) { ya = Math.min(ya, y); yb = Math.max(yb, y); }
    if (!Number.isFinite(ya)) return;
    if (yb <= ya) { yb = ya + 1; }
    let xa = Infinity, xb = -Infinity; for (const x of xs) { xa = Math.min(xa, x); xb = Math.max(xb, x); }
    if (xb <= xa) xb = xa + 1;
    const L = 52, R = w - 8, Tt = 18, Bt = h - 30;
    const px = (x) => L + (x - xa) / (xb - xa) * (R - L), py = (y) => Bt - (y - ya) / (yb - ya) * (Bt - Tt);
    g.font = "11px sans-serif"; g.fillStyle = "#222"; g.textAlign = "left"; g.fillText(title, L, 12);
    g.strokeStyle = "#999"; g.lineWidth = 1; g.strokeRect(L, Tt, R - L, Bt - Tt);
    g.textAlign = "right"; for (const t of niceTicks(ya, yb, 4)) { g.fillText(tickLabel(t), L - 4, py(t) + 4); }
    g.textAlign = "center"; for (const t of niceTicks(xa, xb, 5)) { g.fillText(tickLabel(t), px(t), Bt + 13); }
    g.fillText(xKey, (L + R) / 2, h - 3);
    keys.forEach((k, i) => {
      g.strokeStyle = PALETTE[i % PALETTE.length]; g.lineWidth = 1.5; g.beginPath();
      SER[k].forEach((y, s) => { if (s === 0) g.moveTo(px(xs[s]), py(y)); else g.lineTo(px(xs[s]), py(y)); }); g.stroke();
    });
    g.textAlign = "left";
    const shown = keys.length > 6 ? [] : keys;
    shown.forEach((k, i) => { g.fillStyle = PALETTE[i % PALETTE.length]; g.fillText(k, L + 6, Tt + 12 + 12 * i); });
    if (keys.length > 6) { g.fillStyle = "#222"; g.fillText(`${keys.length} lines`, L + 6, Tt + 12); }
    g.strokeStyle = "#000"; g.setLineDash([3, 3]); g.beginPath(); g.moveTo(px(xs[V.state]), Tt); g.lineTo(px(xs[V.state]), Bt); g.stroke(); g.setLineDash([]);
  }
  function drawCharts() {
    const box = document.getElementById("charts");
    D.charts.forEach((ch, i) => chart(box.children[i], ch.title, ch.keys));
  }

  // ---------------------------------------------------------------- controls
  const slider = document.getElementById("state"), label = document.getElementById("statelabel"), modeSel = document.getElementById("mode");
  slider.max = S - 1;
  for (const m in MODES) { const o = document.createElement("option"); o.value = m; o.textContent = MODES[m].label.split(" (")[0].split(":")[0]; modeSel.appendChild(o); }
  function setState(s) {
    V.state = Math.max(0, Math.min(S - 1, s | 0)); slider.value = V.state;
    const x = D.x_key !== "state" ? `, ${D.x_key} ${fmt(SER[D.x_key][V.state], 4)}` : "";
    label.textContent = `state ${V.state} of ${S - 1}${x}`;
    update(true); drawCharts();
    if (V.hover >= 0) tip.textContent = tipText(V.hover);
  }
  function setMode(m) { if (!MODES[m]) return; V.mode = m; modeSel.value = m; update(true); drawBar(); }
  slider.addEventListener("input", () => setState(+slider.value));
  modeSel.addEventListener("change", () => setMode(modeSel.value));
  let timer = null;
  const play = document.getElementById("play");
  play.addEventListener("click", () => {
    if (timer) { clearInterval(timer); timer = null; play.textContent = "\u25b6 play"; return; }
    play.textContent = "\u275a\u275a pause";
    timer = setInterval(() => setState(V.state >= S - 1 ? 0 : V.state + 1), Math.max(40, 3000 / S));
  });
  const redraw = () => { if (V.ready) { drawCP(); drawBar(); drawCharts(); draw(); } };
  window.addEventListener("resize", redraw);
  // a frame laid out after the script ran (Jupyter output, a hidden tab) has no window resize
  if (window.ResizeObserver) { const ro = new ResizeObserver(redraw); ro.observe(cv); ro.observe(cpc); }

  const sum = document.getElementById("summary");
  for (const [k, v] of Object.entries(D.summary)) {
    const tr = document.createElement("tr");
    tr.innerHTML = "<td></td><td></td>"; tr.children[0].textContent = k;
    tr.children[1].textContent = typeof v === "number" ? fmt(v, 4) : String(v);
    sum.appendChild(tr);
  }
  if (gl) setup();
  timing.setup = performance.now() - T0;
  drawCP();
  timing.pattern = performance.now() - T0;
  setMode(E ? "fold" : "displacement");
  timing.mode = performance.now() - T0;
  setState(S - 1);
  timing.ready = performance.now() - T0;
  V.ready = true;
  // for tests and scripts: drive the viewer and read what it shows
  window.barhingeViewer = {
    get state() { return V.state; }, get mode() { return V.mode; }, get ready() { return V.ready; },
    get drawn() { return V.drawn || 0; },
    modes: Object.keys(MODES), setState, setMode, field: (m, s) => Array.from(MODES[m].f(s)),
    creasePoint: (e) => { const tr = cpTransform(), a = tr(CR[2 * e]), b = tr(CR[2 * e + 1]); return [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2]; },
    camera: cam, timing, positions: (s) => Array.from(pos(s)), eps: EPS,
  };
})();
