// latvox view: the page. It asks the server for the part as shader numbers, draws it with the
// sphere-tracing fragment shader (trace.glsl), orbits with the mouse, and sends edited settings
// back. `window.latvox` exposes the state for scripts (frames drawn, camera, a hit mask, fps).
'use strict';

const FOV = 30; // degrees, vertical: as `latvox render`
const query = new URLSearchParams(location.search);
// The run's secret, from the URL `latvox view` printed: every request to the server carries it.
const TOKEN = query.get('token') || '';
const canvas = document.getElementById('view');
const gl = canvas.getContext('webgl2', { preserveDrawingBuffer: true, antialias: false });
const $ = (id) => document.getElementById(id);

const state = {
  part: null,        // the server's /api/part answer
  settings: null,    // the settings being edited
  scene: null,       // the scene drawn
  camera: { azimuth: 45, elevation: Math.atan(1 / Math.SQRT2) * 180 / Math.PI, distance: null },
  level: null,       // the level (TPMS) or radius (struts) drawn
  section: null,     // { axis, at, above }
  frames: 0,
  version: 0,        // scenes received
  busy: false,
  error: null,
};
window.latvox = state;

function status(text, error) {
  const s = $('status');
  s.textContent = text || '';
  s.className = error ? 'error' : '';
  if (error) state.error = text;
}

// ---------------------------------------------------------------------------------- camera

function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
function cross(a, b) {
  return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
}
function normalized(a) {
  const n = Math.hypot(a[0], a[1], a[2]);
  return n > 0 ? a.map((x) => x / n) : a;
}

// As Camera::looking_at in src/render/camera.rs.
function camera(width, height) {
  const [lo, hi] = state.scene.bounds;
  const centre = [0, 1, 2].map((a) => 0.5 * (lo[a] + hi[a]));
  const s = sub(hi, lo);
  const radius = 0.5 * Math.hypot(s[0], s[1], s[2]);
  const aspect = width / height;
  const halfV = (0.5 * FOV) * Math.PI / 180;
  const half = aspect < 1 ? Math.atan(Math.tan(halfV) * aspect) : halfV;
  const distance = state.camera.distance || 1.04 * radius / Math.sin(half);
  const az = state.camera.azimuth * Math.PI / 180;
  const el = state.camera.elevation * Math.PI / 180;
  const towards = [Math.sin(az) * Math.cos(el), -Math.cos(az) * Math.cos(el), Math.sin(el)];
  const eye = [0, 1, 2].map((a) => centre[a] + distance * towards[a]);
  const forward = towards.map((x) => -x);
  const worldUp = Math.abs(Math.cos(el)) < 1e-9 ? [-Math.sin(az), Math.cos(az), 0] : [0, 0, 1];
  const right = normalized(cross(forward, worldUp));
  const up = cross(right, forward);
  return { eye, forward, right, up, distance };
}

// ---------------------------------------------------------------------------------- WebGL

let program = null;
const textures = {};

function compile(type, source) {
  const sh = gl.createShader(type);
  gl.shaderSource(sh, source);
  gl.compileShader(sh);
  if (!gl.getShaderParameter(sh, gl.COMPILE_STATUS)) {
    throw new Error('shader: ' + gl.getShaderInfoLog(sh));
  }
  return sh;
}

let shaderSource = null;
// Compiled programs, by whether they draw filled parts, with their uniforms' locations.
const variants = {};
let uniforms = {};

async function setupGl() {
  shaderSource = await (await fetch('/trace.glsl')).text();
  const buffer = gl.createBuffer();
  gl.bindBuffer(gl.ARRAY_BUFFER, buffer);
  gl.bufferData(gl.ARRAY_BUFFER, new Float32Array([-1, -1, 1, -1, -1, 1, 1, 1]), gl.STATIC_DRAW);
  ['uStruts', 'uPartNodes', 'uPartTris', 'uKeepNodes', 'uKeepTris', 'uBinTex', 'uSeeds', 'uPores',
    'uPoreBins'].forEach((name, unit) => {
    textures[name] = { texture: gl.createTexture(), unit };
  });
}

// Uses the program for lattice blocks or for filled parts (the shader with FILL 0 or 1: a
// block's shader holds none of the BVH code, which software WebGL runs far faster).
function useVariant(fill) {
  const key = fill ? 1 : 0;
  if (!variants[key]) {
    const vertex = '#version 300 es\nin vec2 corner;\nvoid main() { gl_Position = vec4(corner, 0.0, 1.0); }\n';
    const fragment = shaderSource.replace('#version 300 es\n', `#version 300 es\n#define FILL ${key}\n`);
    const p = gl.createProgram();
    gl.attachShader(p, compile(gl.VERTEX_SHADER, vertex));
    gl.attachShader(p, compile(gl.FRAGMENT_SHADER, fragment));
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) {
      throw new Error('shader: ' + gl.getProgramInfoLog(p));
    }
    const found = {};
    const n = gl.getProgramParameter(p, gl.ACTIVE_UNIFORMS);
    for (let i = 0; i < n; i++) {
      const name = gl.getActiveUniform(p, i).name.replace(/\[0\]$/, '');
      found[name] = gl.getUniformLocation(p, name);
    }
    variants[key] = { program: p, uniforms: found };
  }
  program = variants[key].program;
  uniforms = variants[key].uniforms;
  gl.useProgram(program);
  const at = gl.getAttribLocation(program, 'corner');
  gl.enableVertexAttribArray(at);
  gl.vertexAttribPointer(at, 2, gl.FLOAT, false, 0, 0);
}

function set(name, kind, ...values) {
  const u = uniforms[name];
  if (u !== undefined && u !== null) gl['uniform' + kind](u, ...values);
}

// Rows of numbers as an RGBA float texture for the sampler `name`, `texels` texels a row,
// 1024 texels a line of the texture (as the shader's fetch reads them).
function upload(name, rows, texels) {
  const width = 1024;
  const count = Math.max(1, rows.length * texels);
  const lines = Math.ceil(count / width);
  const data = new Float32Array(width * lines * 4);
  const per = 4 * texels;
  rows.forEach((v, i) => data.set(v, per * i));
  const t = textures[name];
  gl.activeTexture(gl.TEXTURE0 + t.unit);
  gl.bindTexture(gl.TEXTURE_2D, t.texture);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
  gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
  gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, width, lines, 0, gl.RGBA, gl.FLOAT, data);
  set(name, '1i', t.unit);
}

// A triangle's three corners as three texels (the fourth number unused).
function corners(t) {
  return [t[0], t[1], t[2], 0, t[3], t[4], t[5], 0, t[6], t[7], t[8], 0];
}

// Loads the scene's numbers into the shader.
function loadScene(scene) {
  let [lo, hi] = scene.bounds;
  const f = scene.fill;
  useVariant(Boolean(f));
  if (f) {
    // A small step past a surface a ray was cast to, and the box grown by it.
    const nudge = 2e-5 * (1 + Math.max(...sub(hi, lo)));
    lo = lo.map((x) => x - nudge);
    hi = hi.map((x) => x + nudge);
    set('uNudge', '1f', nudge);
    upload('uPartNodes', f.part.nodes, 2);
    upload('uPartTris', f.part.triangles.map(corners), 3);
    upload('uKeepNodes', f.keep.nodes, 2);
    upload('uKeepTris', f.keep.triangles.map(corners), 3);
    set('uKeepCount', '1i', f.keep.triangles.length);
    set('uSkin', '1f', f.skin);
    set('uFillBlend', '1f', f.blend);
    set('uCap', '1f', f.cap);
    const drains = new Float32Array(128);
    f.drains.slice(0, 16).forEach((d, i) => drains.set([d[0], d[1], d[2], d[6], d[3], d[4], d[5], 0], 8 * i));
    set('uDrainCount', '1i', Math.min(16, f.drains.length));
    set('uDrains', '4fv', drains);
  }
  set('uBoxMin', '3fv', lo);
  set('uBoxMax', '3fv', hi);
  set('uStep', '1f', 0.1 * scene.voxel);
  set('uAoReach', '1f', scene.cell / 6);
  if (scene.kind === 'tpms') {
    const t = scene.tpms;
    const terms = new Float32Array(40);
    t.terms.forEach((row, i) => terms.set(row, 4 * i));
    set('uKind', '1i', 0);
    set('uTerms', '4fv', terms);
    set('uTermCount', '1i', t.terms.length);
    set('uSheet', '1i', t.sheet ? 1 : 0);
    set('uLipschitz', '1f', t.lipschitz);
    set('uReach', '1f', scene.reach);
    set('uCell', '3fv', t.size);
    set('uPhase', '3fv', t.phase);
  } else if (scene.kind === 'walls') {
    const w = scene.walls;
    upload('uSeeds', w.seeds, 1);
    upload('uBinTex', w.bins.map((b) => [b, 0, 0, 0]), 1);
    upload('uPores', w.pores, 3);
    upload('uPoreBins', w.pore_bins.map((b) => [b, 0, 0, 0]), 1);
    set('uKind', '1i', 2);
    set('uBins', '3i', ...w.bins_per_axis);
    set('uRepeat', '1i', w.periodic ? 1 : 0);
    set('uReach', '1f', scene.reach);
    set('uCell', '3fv', w.size);
    set('uPhase', '3fv', w.phase);
  } else {
    const s = scene.struts;
    upload('uStruts', s.struts, 2);
    upload('uBinTex', s.bins.map((b) => [b, 0, 0, 0]), 1);
    set('uKind', '1i', 1);
    set('uBins', '3i', ...s.bins_per_axis);
    set('uBlend', '1f', s.blend);
    set('uReach', '1f', scene.reach);
    set('uCell', '3fv', s.size);
    set('uPhase', '3fv', s.phase);
  }
}

function size() {
  const w = parseInt(query.get('width'), 10);
  const h = parseInt(query.get('height'), 10);
  if (w > 0 && h > 0) return [w, h];
  const r = $('stage').getBoundingClientRect();
  return [Math.max(1, Math.floor(r.width)), Math.max(1, Math.floor(r.height))];
}

// Draws one frame now; `coarse`: every `coarse`-th pixel along each axis, stretched (while
// the part is being turned on a slow machine).
function draw(coarse) {
  if (!program || !state.scene) return;
  const [fw, fh] = size();
  const k = coarse || 1;
  const w = Math.max(1, Math.round(fw / k));
  const h = Math.max(1, Math.round(fh / k));
  if (canvas.width !== w || canvas.height !== h) {
    canvas.width = w;
    canvas.height = h;
  }
  canvas.style.width = fw + 'px';
  canvas.style.height = fh + 'px';
  gl.viewport(0, 0, w, h);
  const c = camera(w, h);
  set('uSize', '2f', w, h);
  set('uEye', '3fv', c.eye);
  set('uForward', '3fv', c.forward);
  set('uRight', '3fv', c.right);
  set('uUp', '3fv', c.up);
  set('uTanHalf', '1f', Math.tan((0.5 * FOV) * Math.PI / 180));
  set('uLevel', '1f', state.level);
  const sec = state.section;
  set('uSectionOn', '1i', sec ? 1 : 0);
  if (sec) {
    const n = [0, 0, 0];
    n[sec.axis] = sec.above ? -1 : 1;
    set('uSectionN', '3fv', n);
    set('uSectionD', '1f', sec.above ? -sec.at : sec.at);
  }
  gl.clearColor(0, 0, 0, 0);
  gl.clear(gl.COLOR_BUFFER_BIT);
  gl.drawArrays(gl.TRIANGLE_STRIP, 0, 4);
  state.frames += 1;
  $('hud').textContent = `${w}×${h} · azimuth ${state.camera.azimuth.toFixed(0)}° · elevation `
    + `${state.camera.elevation.toFixed(0)}° · ${c.distance.toFixed(1)} mm`;
}

// While the mouse turns or zooms the part, frames are drawn coarser when a full one is slow
// (software WebGL), and the full frame follows once it rests.
let pending = false;
let fullMs = 0;
let moving = 0;
let settle = null;
function requestDraw(interactive) {
  if (interactive) {
    moving = performance.now();
    clearTimeout(settle);
    settle = setTimeout(() => requestDraw(false), 250);
  }
  if (pending) return;
  pending = true;
  requestAnimationFrame(() => {
    pending = false;
    const busy = performance.now() - moving < 250;
    const coarse = !busy ? 1 : fullMs > 400 ? 4 : fullMs > 60 ? 2 : 1;
    const t0 = performance.now();
    draw(coarse);
    if (coarse === 1) {
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
      fullMs = performance.now() - t0;
    }
  });
}

// Frames per second over `n` frames, each waited for.
state.bench = function (n) {
  const px = new Uint8Array(4);
  draw();
  gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
  const t0 = performance.now();
  for (let i = 0; i < n; i++) {
    draw();
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, px);
  }
  return n / ((performance.now() - t0) / 1000);
};

// The last frame's pixels, RGBA row by row from the top.
function framePixels() {
  const w = canvas.width;
  const h = canvas.height;
  const px = new Uint8Array(w * h * 4);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
  const top = new Uint8Array(w * h * 4);
  for (let y = 0; y < h; y++) top.set(px.subarray(4 * w * (h - 1 - y), 4 * w * (h - y)), 4 * w * y);
  return top;
}

// The hit mask of the last frame, top row first: '1' where a ray met the part.
state.mask = function () {
  const px = framePixels();
  let out = '';
  for (let i = 3; i < px.length; i += 4) out += px[i] > 127 ? '1' : '0';
  return out;
};

// The last frame's colours, RGB row by row from the top, base64: what the page shows.
state.pixels = function () {
  const px = framePixels();
  let out = '';
  for (let i = 0; i < px.length; i += 4) out += String.fromCharCode(px[i], px[i + 1], px[i + 2]);
  return btoa(out);
};

state.setCamera = function (c) {
  Object.assign(state.camera, c);
  draw();
};

// ---------------------------------------------------------------------------------- server

async function call(method, path, body) {
  const headers = { Authorization: `token ${TOKEN}` };
  if (body) headers['Content-Type'] = 'application/json';
  const r = await fetch(path, {
    method,
    headers,
    body: body ? JSON.stringify(body) : undefined,
  });
  const answer = await r.json();
  if (!r.ok) throw new Error(answer.error || r.statusText);
  return answer;
}

function useScene(scene) {
  state.scene = scene;
  state.level = scene.level;
  state.version += 1;
  loadScene(scene);
  showLevel();
  sectionRange();
  draw();
}

let asked = 0;
async function rescene() {
  const mine = ++asked;
  status('drawing the new part…');
  try {
    const answer = await call('POST', '/api/scene', { settings: state.settings });
    if (mine !== asked) return;
    state.error = null;
    status('');
    useScene(answer.scene);
  } catch (e) {
    if (mine === asked) status(e.message, true);
  }
}

// ---------------------------------------------------------------------------------- controls

// The settings the panel always offers, per command, beside those the file gives.
const OFFERED = {
  tpms: ['type', 'structure', 'density', 'cells', 'cell-size', 'size'],
  strut: ['cell', 'density', 'radius', 'blend', 'cells', 'cell-size', 'size'],
  fill: ['lattice', 'structure', 'cell-size', 'density', 'skin', 'blend', 'drain'],
};

function textOf(v) {
  if (v === undefined || v === null) return '';
  return Array.isArray(v) ? v.join(',') : String(v);
}

function valueOf(text) {
  const t = text.trim();
  if (t === '') return undefined;
  const number = (s) => (s.trim() !== '' && !isNaN(Number(s)) ? Number(s) : undefined);
  if (number(t) !== undefined) return number(t);
  if (t.includes(',')) {
    const items = t.split(',').map(number);
    if (items.every((x) => x !== undefined)) return items;
  }
  return t;
}

function buildSettings() {
  const box = $('settings');
  box.innerHTML = '';
  const command = state.settings.command;
  const keys = [...new Set([...(OFFERED[command] || []), ...Object.keys(state.settings)])]
    .filter((k) => k !== 'command');
  for (const key of keys) {
    const row = document.createElement('label');
    const name = document.createElement('span');
    name.textContent = key;
    row.appendChild(name);
    const choices = state.part.choices[key];
    let input;
    const value = state.settings[key];
    if (typeof value === 'boolean') {
      input = document.createElement('input');
      input.type = 'checkbox';
      input.checked = value;
    } else if (choices && (value === undefined || choices.includes(value))) {
      input = document.createElement('select');
      for (const c of choices) {
        const o = document.createElement('option');
        o.value = c;
        o.textContent = c;
        input.appendChild(o);
      }
      input.value = value === undefined ? choices[0] : value;
      if (value === undefined) state.settings[key] = input.value;
    } else {
      input = document.createElement('input');
      input.type = 'text';
      input.value = textOf(value);
      input.placeholder = 'default';
    }
    input.id = 'set-' + key;
    input.addEventListener('change', () => {
      const v = input.type === 'checkbox' ? input.checked : input.tagName === 'SELECT'
        ? input.value : valueOf(input.value);
      if (v === undefined) delete state.settings[key]; else state.settings[key] = v;
      // Density and radius exclude each other: the one edited wins.
      if (key === 'density' && v !== undefined) {
        for (const k of ['radius', 'thickness']) { delete state.settings[k]; $('set-' + k) && ($('set-' + k).value = ''); }
      }
      if ((key === 'radius' || key === 'thickness') && v !== undefined) { delete state.settings.density; $('set-density') && ($('set-density').value = ''); }
      rescene();
    });
    row.appendChild(input);
    box.appendChild(row);
  }
}

// The part's setting the level control edits (a strut or Voronoi net's radius, a Voronoi
// sheet's thickness), or null where it previews another level than the density's.
function levelSetting() {
  const c = state.settings.command;
  if (state.scene.kind === 'struts' && (c === 'strut' || c === 'voronoi')) return 'radius';
  if (state.scene.kind === 'walls' && c === 'voronoi') return 'thickness';
  return null;
}

// The largest radius or thickness the scene's lists hold every strut or seed for.
function levelMax() {
  return state.scene.kind === 'walls' ? state.scene.walls.max_thickness : state.scene.struts.max_radius;
}

function showLevel() {
  const sized = state.scene.kind !== 'tpms';
  const name = state.scene.kind === 'walls' ? 'thickness' : 'radius';
  $('levelName').textContent = sized ? `${name} (mm)` : 'level';
  $('level').value = state.level.toPrecision(4);
  $('level').step = sized ? (state.level / 20).toPrecision(2) : '0.01';
  $('levelNote').textContent = levelSetting()
    ? `The ${name} draws at once and is saved as the part's ${name}.`
    : `The ${sized ? name : 'level'} the density gives; another is a preview (the density sets the saved part).`;
}

function sectionRange() {
  const axis = $('sectionAxis').value;
  if (axis === '') return;
  const [lo, hi] = state.scene.bounds;
  const a = Number(axis);
  const slider = $('sectionAt');
  slider.min = lo[a];
  slider.max = hi[a];
  slider.step = (hi[a] - lo[a]) / 1000;
  if (!state.section || state.section.axis !== a) slider.value = 0.5 * (lo[a] + hi[a]);
  updateSection();
}

function updateSection() {
  const axis = $('sectionAxis').value;
  state.section = axis === '' ? null
    : { axis: Number(axis), at: Number($('sectionAt').value), above: $('sectionFlip').checked };
  requestDraw();
}

function wire() {
  $('level').addEventListener('input', () => {
    const v = Number($('level').value);
    if (!isFinite(v)) return;
    const sized = state.scene.kind !== 'tpms';
    if (sized && !(v > 0)) return;
    const key = levelSetting();
    if (sized && !key) {
      // A preview within the size the lists hold every strut or seed for.
      state.level = Math.min(v, levelMax());
      requestDraw();
      return;
    }
    if (key) {
      state.settings[key] = Number(v.toPrecision(6));
      delete state.settings.density;
      if ($('set-' + key)) $('set-' + key).value = state.settings[key];
      if ($('set-density')) $('set-density').value = '';
      // Past the size the lists were built for, the server builds longer ones.
      if (v > levelMax()) { rescene(); return; }
    }
    state.level = v;
    requestDraw();
  });
  $('sectionAxis').addEventListener('change', () => {
    if ($('sectionAxis').value === '') updateSection(); else sectionRange();
  });
  $('sectionAt').addEventListener('input', updateSection);
  $('sectionFlip').addEventListener('change', updateSection);
  $('viewName').addEventListener('change', () => {
    const views = { iso: [45, 35.26], front: [0, 0], right: [90, 0], top: [0, 90] };
    const [azimuth, elevation] = views[$('viewName').value];
    state.setCamera({ azimuth, elevation, distance: null });
  });
  let drag = null;
  canvas.addEventListener('pointerdown', (e) => {
    drag = { x: e.clientX, y: e.clientY };
    canvas.setPointerCapture(e.pointerId);
  });
  canvas.addEventListener('pointermove', (e) => {
    if (!drag) return;
    state.camera.azimuth -= 0.4 * (e.clientX - drag.x);
    state.camera.elevation = Math.max(-89, Math.min(89,
      state.camera.elevation + 0.4 * (e.clientY - drag.y)));
    drag = { x: e.clientX, y: e.clientY };
    requestDraw(true);
  });
  canvas.addEventListener('pointerup', () => { drag = null; });
  canvas.addEventListener('wheel', (e) => {
    e.preventDefault();
    const d = state.camera.distance || camera(canvas.width, canvas.height).distance;
    state.camera.distance = d * Math.exp(0.001 * e.deltaY);
    requestDraw(true);
  }, { passive: false });
  window.addEventListener('resize', requestDraw);
  $('save').addEventListener('click', save);
  $('mesh').addEventListener('click', () => run('/api/mesh', { output: $('meshPath').value }));
  $('slice').addEventListener('click', () => run('/api/slice', {
    output: $('slicePath').value, layer: Number($('sliceLayer').value),
  }));
}

async function save() {
  try {
    const answer = await call('POST', '/api/save', { settings: state.settings, path: $('savePath').value });
    state.saved = answer.saved;
    status('saved ' + answer.saved);
  } catch (e) {
    status(e.message, true);
  }
}

async function run(path, body) {
  try {
    await call('POST', path, { settings: state.settings, ...body });
  } catch (e) {
    status(e.message, true);
    return;
  }
  state.busy = true;
  $('busy').hidden = false;
  for (;;) {
    const j = await call('GET', '/api/job');
    if (j.state !== 'running') {
      state.busy = false;
      state.job = j;
      $('busy').hidden = true;
      if (j.state === 'done') {
        const r = j.report || {};
        const density = r.achieved_density !== undefined
          ? ` · density ${Number(r.achieved_density).toFixed(4)}` : '';
        const layers = r.layers !== undefined ? ` · ${r.layers} layers` : '';
        status(`${j.what} done in ${j.seconds.toFixed(1)} s → ${j.output}${density}${layers}`);
      } else {
        status(`${j.what} failed: ${j.message}`, true);
      }
      return;
    }
    status(`${j.what}: ${j.stage} · ${j.seconds.toFixed(0)} s`);
    await new Promise((r) => setTimeout(r, 400));
  }
}

async function main() {
  if (!gl) {
    status('This browser has no WebGL2: the part cannot be drawn here (latvox render draws it on the CPU).', true);
    return;
  }
  try {
    if (!TOKEN) {
      status('This address lacks the editor\'s token: open the URL latvox view printed (…/?token=…).', true);
      return;
    }
    await setupGl();
    state.part = await call('GET', '/api/part');
    state.settings = JSON.parse(JSON.stringify(state.part.settings));
    $('path').textContent = state.part.path;
    $('folder').textContent = `Files are written in ${state.part.folder} (names relative to it).`;
    $('savePath').value = state.part.save;
    buildSettings();
    wire();
    useScene(state.part.scene);
    state.ready = true;
  } catch (e) {
    status(e.message, true);
  }
}

main();
