// The thaw browser client: one WebSocket (subprotocol thaw.v1, docs/PROTOCOL.md) carrying JSON events
// and binary frames (a 28-byte header, then JPEG). Every frame is acknowledged, so the server never
// sends more than it can take; controls are protocol commands. The page shows the server's state: it
// rebuilds its controls from `welcome` and from every `scene` event (a scene loaded, reset or restored
// by any client), and follows the stats, so a reload or a second page shows what the server has.
'use strict';

const $ = (id) => document.getElementById(id);
const canvas = $('view');
const ctx = canvas.getContext('2d');
const plot = $('plot');
const hud = $('hud');

let ws = null;
let nextId = 1;
let welcome = null;
let controller = false;
let paused = false;
let dryers = [];          // the scene's dryers as the server last described them
let lamps = [];           // its lamps
let emitters = [];        // and its taps (emitters), with their flow in L/s
let substances = [];      // and the substances it declares, by name, for substance.drop
let substanceBooks = {};  // each substance's account from the last stats: {total, inflow, closure, ...} [kg]
let tension = 'none';     // the tension model in force (tension.model)
let history = [];         // [sim time, ice fraction or null, mean temperature or null]
let pace = [];            // [wall ms, sim time] of recent stats, for the simulated seconds per wall second
let reconnectDelay = 500;
let framesSeen = 0, fpsWindowStart = performance.now(), fps = 0;

function send(type, fields = {}) {
  if (!ws || ws.readyState !== WebSocket.OPEN) return;
  ws.send(JSON.stringify(Object.assign({ type, id: nextId++ }, fields)));
}

function setState(cls, text) {
  const el = $('connection');
  el.className = 'state ' + cls;
  el.textContent = text;
}

function connect() {
  const url = (location.protocol === 'https:' ? 'wss://' : 'ws://') + location.host + '/';
  ws = new WebSocket(url, 'thaw.v1');  // the server needs the subprotocol by name
  ws.binaryType = 'arraybuffer';
  setState('connecting', 'connecting…');
  ws.onopen = () => {
    reconnectDelay = 500;
    setState('connected', 'connected');
    const token = new URLSearchParams(location.search).get('token');
    send('hello', token ? { version: 1, token } : { version: 1 });
  };
  ws.onclose = () => {
    setState('closed', 'disconnected; retrying');
    setTimeout(connect, reconnectDelay);
    reconnectDelay = Math.min(reconnectDelay * 2, 8000);
  };
  ws.onmessage = (ev) => (typeof ev.data === 'string' ? onEvent(JSON.parse(ev.data)) : onFrame(ev.data));
}

function onFrame(buffer) {
  const view = new DataView(buffer);
  if (buffer.byteLength < 28 || view.getUint32(0, true) !== 0x31464854) return;  // "THF1"
  const frame = Number(view.getBigUint64(4, true));
  const length = view.getUint32(24, true);
  send('frame.ack', { frame });
  const blob = new Blob([new Uint8Array(buffer, 28, length)], { type: 'image/jpeg' });
  createImageBitmap(blob).then((bitmap) => {
    if (canvas.width !== bitmap.width || canvas.height !== bitmap.height) {
      canvas.width = bitmap.width;
      canvas.height = bitmap.height;
    }
    ctx.drawImage(bitmap, 0, 0);
    bitmap.close();
    framesSeen++;
    const now = performance.now();
    if (now - fpsWindowStart > 1000) {
      fps = (framesSeen * 1000) / (now - fpsWindowStart);
      framesSeen = 0;
      fpsWindowStart = now;
    }
  });
}

// ---- the scene state: every control from what the server says --------------------------------------

function indices(list) {
  return list.map((_, i) => String(i));
}

// A select keeps the user's choice when the list it offers is the same length as before.
function fillIndexSelect(select, list) {
  const keep = select.options.length === list.length ? select.value : '0';
  fillSelect(select, indices(list), keep);
}

function applyScene(m) {
  $('scene-name').textContent = m.scene;
  $('scene-name').title = m.description || '';
  fillSelect($('scene'), (welcome && welcome.scenes) || [], m.scene);
  dryers = m.dryers || [];
  lamps = m.lamps || [];
  emitters = m.emitters || [];
  substances = m.substances || [];
  fillSelect($('substance'), substances.map((x) => x.name), substances.length ? substances[0].name : '');
  // The colourings: the fixed three, then each of the scene's substances (g/L).
  const colour = $('colour-by');
  for (const o of [...colour.options]) if (o.value.startsWith('substance:')) o.remove();
  for (const x of substances) {
    const o = document.createElement('option');
    o.value = `substance:${x.name}`;
    o.textContent = `by ${x.name} (g/L)`;
    // Its colour: what the surface view tints the water with.
    if (x.colour) o.style.color = x.colour;
    colour.appendChild(o);
  }
  fillSelect($('dryer'), indices(dryers), '0');
  fillSelect($('lamp'), indices(lamps), '0');
  fillSelect($('emitter'), indices(emitters), '0');
  applyLists();
  applyView(m.view, m.quality);
  applyPace(m.speed, m.heat_time_scale, m.tension);
  applyPaused(m.paused);
  // A run that stopped publishes no stats: say why now, as the stats would.
  if (m.error) hud.textContent = `stopped: ${m.error}`;
  history = [];
  pace = [];
  drawPlot();
}

function applyLists() {
  $('dryers').hidden = dryers.length === 0;
  $('lamps').hidden = lamps.length === 0;
  $('taps').hidden = emitters.length === 0;
  $('substances').hidden = substances.length === 0;
  if (substances.length === 0 && $('drop').checked) {
    $('drop').checked = false;
    canvas.classList.remove('aiming');
  }
  showDryer();
  showLamp();
  showEmitter();
}

function applyView(view, quality) {
  if (view) {
    $('view-kind').value = view.view;
    $('colour-by').value = view.colour_by;
    if (view.tint_reference !== undefined) showChoice('tint-reference', view.tint_reference, (v) => `${v} g/L`);
  }
  if (quality && quality.surface) $('full-quality').checked = quality.surface === 'full';
  if (quality && quality.scale !== undefined) showChoice('scale', quality.scale, (v) => `${Math.round(100 * Number(v))} %`);
}

// What the frame on screen is in the surface view: its quality and the size its march drew, stretched to
// the image (the server draws frames at half the width and height while the camera moves).
function frameQuality(m) {
  if (!m.view || m.view.view !== 'surface' || !m.quality || m.frame_scale === undefined) return '';
  const w = Math.round(m.quality.width * m.frame_scale), h = Math.round(m.quality.height * m.frame_scale);
  const size = m.frame_scale < 1 ? `${w}×${h} stretched` : `${w}×${h}`;
  return `   ${m.frame_moving ? 'moving' : m.quality.surface} ${size}`;
}

// A menu shows the server's value, adding it as an option when another client chose one not listed;
// the menu being used keeps the user's choice.
function showChoice(id, value, label) {
  const select = $(id);
  if (value === undefined || document.activeElement === select) return;
  const v = String(value);
  if (![...select.options].some((o) => o.value === v)) {
    const o = document.createElement('option');
    o.value = v;
    o.textContent = label(v);
    select.appendChild(o);
  }
  select.value = v;
}

function applyPace(speed, heatScale, tensionModel) {
  showChoice('speed', speed, (v) => `${v} × real time`);
  showChoice('heat-scale', heatScale, (v) => `× ${v}`);
  showChoice('tension', tensionModel, (v) => v);
  if (tensionModel !== undefined) tension = tensionModel;
}

function applyPaused(p) {
  paused = !!p;
  $('pause').textContent = paused ? 'Resume' : 'Pause';
}

function onEvent(m) {
  switch (m.type) {
    case 'welcome':
      welcome = m;
      controller = m.role === 'controller';
      $('role').textContent = controller ? '' : '(viewer: controls are off)';
      for (const el of document.querySelectorAll('aside input, aside select, aside button'))
        if (!el.classList.contains('anyone')) el.disabled = !controller;
      // The frame is shared by every viewer, so only a controller sets its size.
      if (controller) send('quality.set', { width: canvas.width, height: canvas.height });
      applyScene(m);
      break;
    case 'scene':
      applyScene(m);
      break;
    case 'stats':
      onStats(m);
      break;
    case 'error':
      $('message').textContent = `${m.of || ''} ${m.code}: ${m.message}`;
      break;
    case 'ack':
      $('message').textContent = '';
      break;
  }
}

// Simulated seconds per wall second over the last few seconds of stats.
function simRate() {
  if (pace.length < 2) return null;
  const [w0, t0] = pace[0], [w1, t1] = pace[pace.length - 1];
  return w1 > w0 ? (t1 - t0) / ((w1 - w0) / 1000) : null;
}

// A temperature to `digits` decimals, without the "-0.0" that rounding a hair below zero gives.
function celsius(t, digits) {
  const text = t.toFixed(digits);
  return Number(text) === 0 ? (0).toFixed(digits) : text;
}

function onStats(m) {
  applyPaused(m.paused);
  substanceBooks = m.substances || {};
  showSubstance();
  if (m.dryers) dryers = m.dryers;
  if (m.lamps) lamps = m.lamps;
  if (m.emitters) {
    if (m.emitters.length !== emitters.length) fillIndexSelect($('emitter'), m.emitters);
    emitters = m.emitters;
  }
  applyLists();
  applyView(m.view, m.quality);
  applyPace(m.speed, m.heat_time_scale, m.tension);

  const now = performance.now();
  pace.push([now, m.time]);
  while (pace.length > 2 && now - pace[0][0] > 3000) pace.shift();
  const T = m.temperature;
  history.push([m.time, m.ice_fraction, T ? T.mean : null]);
  if (history.length > 2000) history.splice(0, history.length - 2000);

  const rate = simRate();
  const lines = [
    `t ${m.time.toFixed(3)} s   ` +
      (rate === null ? '' : `${rate < 0.1 ? rate.toPrecision(2) : rate.toFixed(2)} s simulated per s   `) +
      `heat ×${m.heat_time_scale}   ${fps.toFixed(1)} fps` + frameQuality(m),
  ];
  if (m.ice_fraction !== null && m.ice_fraction !== undefined)
    lines.push(`ice ${(1000 * m.ice_mass).toFixed(2)} g (${(100 * m.ice_fraction).toFixed(1)} % of the start)`);
  if (T) lines.push(`T mean ${celsius(T.mean, 2)} °C, ${celsius(T.min, 1)} to ${celsius(T.max, 1)} °C`);
  // With air particles, what comes in and goes out is mostly air (a dryer's jet and its intake, the room's
  // air at open sides), not water poured and run out.
  const A = m.air_temperature, air = m.particles.air || 0;
  if (A) lines.push(`air mean ${celsius(A.mean, 1)} °C, ${celsius(A.min, 1)} to ${celsius(A.max, 1)} °C`);
  lines.push(`particles ${m.particles.water} water, ${m.particles.ice} ice` + (air ? `, ${air} air` : ''));
  // The books on a line of their own: with the air's count the line outgrew the picture.
  const books = (m.inflow ? `${air ? 'came in' : 'poured'} ${(1000 * m.inflow.mass).toFixed(1)} g   ` : '') +
      (m.outflow ? `${air ? 'went out' : 'ran out'} ${(1000 * m.outflow.mass).toFixed(1)} g   ` : '') +
      (m.energy ? `energy closure ${m.energy.closure_relative.toExponential(1)}` : '');
  if (books) lines.push(books);
  if (m.error) lines.push(`stopped: ${m.error}`);
  hud.textContent = lines.join('\n');
  drawPlot();
}

function fillSelect(select, values, current) {
  select.innerHTML = '';
  for (const v of values) {
    const o = document.createElement('option');
    o.value = o.textContent = v;
    if (v === current) o.selected = true;
    select.appendChild(o);
  }
}

// ---- dryers, lamps, taps: the panel shows the selected one as the server has it, except the slider
// a user is dragging ----------------------------------------------------------------------------------

function setSlider(id, value, digits = 0) {
  if (document.activeElement !== $(id)) $(id).value = value;
  $(id + '-out').textContent = Number(value).toFixed(digits);
}

function currentDryer() {
  return Number($('dryer').value || 0);
}

function showDryer() {
  const d = dryers[currentDryer()];
  if (!d) return;
  $('dryer-on').checked = d.on;
  setSlider('dryer-temp', d.temperature);
  setSlider('dryer-speed', d.speed, 1);
}

function currentLamp() {
  return Number($('lamp').value || 0);
}

function showLamp() {
  const l = lamps[currentLamp()];
  if (!l) return;
  $('lamp-on').checked = l.on;
  setSlider('lamp-temp', l.temperature);
}

function currentEmitter() {
  return Number($('emitter').value || 0);
}

function showEmitter() {
  const e = emitters[currentEmitter()];
  if (!e) return;
  $('emitter-open').checked = e.open;
  setSlider('emitter-rate', e.rate, 3);
  setSlider('emitter-temp', e.temperature);
}

// ---- the plot: ice left in % of the start (left axis) and the mean temperature (right axis) against
// simulated time ---------------------------------------------------------------------------------------

// Round bounds that hold [lo, hi] and span at least `least`.
function niceRange(lo, hi, least) {
  const mid = (lo + hi) / 2;
  if (hi - lo < least) [lo, hi] = [mid - least / 2, mid + least / 2];
  const step = Math.pow(10, Math.floor(Math.log10(hi - lo)));
  return [Math.floor(lo / step) * step, Math.ceil(hi / step) * step];
}

function drawPlot() {
  const g = plot.getContext('2d');
  const W = plot.width, H = plot.height, left = 34, right = 40, top = 16, bottom = 22;
  g.clearRect(0, 0, W, H);
  g.font = '10px system-ui, sans-serif';
  g.strokeStyle = '#555';
  g.strokeRect(left, top, W - left - right, H - top - bottom);
  if (history.length < 2) {
    g.fillStyle = '#999';
    g.fillText('waiting for the simulation…', left + 8, top + 20);
    return;
  }
  const t0 = history[0][0], t1 = Math.max(history[history.length - 1][0], t0 + 1e-9);
  const x = (t) => left + ((t - t0) / (t1 - t0)) * (W - left - right);
  const y = (f) => top + (1 - f) * (H - top - bottom);
  const line = (value, colour) => {
    g.strokeStyle = colour;
    g.beginPath();
    let started = false;
    for (const h of history) {
      const v = value(h);
      if (v === null) continue;
      started ? g.lineTo(x(h[0]), y(v)) : g.moveTo(x(h[0]), y(v));
      started = true;
    }
    g.stroke();
  };
  g.fillStyle = '#ccc';
  g.textAlign = 'center';
  g.fillText(`${t0.toFixed(2)}`, left, H - 8);
  g.fillText(`${t1.toFixed(2)} s simulated`, W - right - 30, H - 8);
  const hasIce = history.some((h) => h[1] !== null && h[1] !== undefined);
  if (hasIce) {
    line((h) => (h[1] === null || h[1] === undefined ? null : Math.min(1, Math.max(0, h[1]))), '#9fd8ff');
    g.fillStyle = '#9fd8ff';
    g.textAlign = 'right';
    g.fillText('100 %', left - 3, top + 4);
    g.fillText('0 %', left - 3, H - bottom + 3);
    g.textAlign = 'left';
    g.fillText('ice left', left + 4, top - 4);
  }
  const temps = history.map((h) => h[2]).filter((v) => v !== null);
  if (temps.length) {
    // At least 2 °C tall, so round-off does not fill the plot with noise.
    const [lo, hi] = niceRange(Math.min(...temps), Math.max(...temps), 2);
    line((h) => (h[2] === null ? null : (h[2] - lo) / (hi - lo)), '#ff9f6b');
    g.fillStyle = '#ff9f6b';
    g.textAlign = 'left';
    g.fillText(`${hi} °C`, W - right + 3, top + 4);
    g.fillText(`${lo} °C`, W - right + 3, H - bottom + 3);
    g.textAlign = 'right';
    g.fillText('mean temperature', W - right - 4, top - 4);
  }
}

// ---- the canvas: orbit by dragging, zoom by the wheel; with "aim" ticked, a click or drag aims the
// dryer at the surface under the pointer (the server picks it from the same field it renders) --------
let drag = null;
canvas.addEventListener('pointerdown', (e) => {
  drag = { x: e.offsetX, y: e.offsetY };
  canvas.setPointerCapture(e.pointerId);
  if ($('aim').checked) aimAt(e);
  if ($('drop').checked) dropAt(e);
});
canvas.addEventListener('pointermove', (e) => {
  if (!drag) return;
  if ($('aim').checked) {
    aimAt(e);
    return;
  }
  if ($('drop').checked) return;  // one dose a click
  const dx = e.offsetX - drag.x, dy = e.offsetY - drag.y;
  drag = { x: e.offsetX, y: e.offsetY };
  if (dx || dy) send('camera.orbit', { d_azimuth: -0.4 * dx, d_elevation: 0.4 * dy });
});
canvas.addEventListener('pointerup', () => (drag = null));
canvas.addEventListener('wheel', (e) => {
  e.preventDefault();
  send('camera.orbit', { zoom: e.deltaY > 0 ? 1.1 : 1 / 1.1 });
}, { passive: false });

let lastAim = 0;
function aimAt(e) {
  const now = performance.now();
  if (now - lastAim < 50) return;  // the server rate-limits commands; a drag needs no more than 20 a second
  lastAim = now;
  const sx = canvas.width / canvas.clientWidth, sy = canvas.height / canvas.clientHeight;
  send('dryer.aim', { dryer: currentDryer(), x: e.offsetX * sx, y: e.offsetY * sy });
}

// How much of the chosen substance the scene holds, and how much was dropped or poured in; of what it holds,
// how much sits on the water's surface (a detergent) and on solids and ice (a coating), where it can.
function showSubstance() {
  const b = substanceBooks[$('substance').value];
  // In g, mg or µg, whichever reads without an exponent once rounded to three digits (0.9999 g is "1.00 g",
  // not "1.00e+3 mg").
  const mass = (kg) => kg >= 0.9995e-3 ? `${(1e3 * kg).toPrecision(3)} g`
                     : kg >= 0.9995e-6 ? `${(1e6 * kg).toPrecision(3)} mg` : `${(1e9 * kg).toPrecision(3)} µg`;
  let text = b ? `${mass(b.total)} held` : '';
  if (b && b.inflow > 0) text += `, ${mass(b.inflow)} added`;
  if (b && b.on_surface > 0) text += `; ${mass(b.on_surface)} on the surface`;
  if (b && b.on_solids > 0) text += `; ${mass(b.on_solids)} on solids and ice`;
  // Past what the melt dissolves (its solubility), or held by ice with no melt: salt that sits undissolved.
  if (b && b.undissolved > 1e-6 * b.total) text += `; ${mass(b.undissolved)} undissolved`;
  $('substance-total').textContent = text;
}
$('substance').addEventListener('change', showSubstance);

// A dose of the chosen substance where the surface under the pointer is (the server picks it as for aim).
function dropAt(e) {
  const sx = canvas.width / canvas.clientWidth, sy = canvas.height / canvas.clientHeight;
  send('substance.drop', {
    substance: $('substance').value,
    amount: Number($('substance-amount').value),
    x: e.offsetX * sx,
    y: e.offsetY * sy,
  });
}

// ---- controls -> commands ---------------------------------------------------------------------------
// Aiming a dryer and dropping a substance both take the canvas's clicks: one at a time.
$('aim').addEventListener('change', () => {
  if ($('aim').checked) $('drop').checked = false;
  canvas.classList.toggle('aiming', $('aim').checked || $('drop').checked);
});
$('drop').addEventListener('change', () => {
  if ($('drop').checked) $('aim').checked = false;
  canvas.classList.toggle('aiming', $('aim').checked || $('drop').checked);
});
$('pause').addEventListener('click', () => send(paused ? 'sim.resume' : 'sim.pause'));
$('step').addEventListener('click', () => send('sim.step', { n: 10 }));
$('reset').addEventListener('click', () => send('sim.reset'));
$('reset-view').addEventListener('click', () => send('camera.reset'));
$('scene').addEventListener('change', (e) => send('scene.load', { name: e.target.value }));
$('speed').addEventListener('change', (e) => send('sim.speed', { factor: Number(e.target.value) }));
// A new heat time scale rebuilds the simulation from its particles (param.set's rebuild).
$('heat-scale').addEventListener('change', (e) =>
  send('param.set', { path: 'heat.time_scale', value: Number(e.target.value) }));
// So does a new tension model (docs/TENSION.md).
$('tension').addEventListener(
    'change', (e) => send('param.set', {path: 'tension.model', value: e.target.value}));

$('dryer').addEventListener('change', showDryer);
$('dryer-on').addEventListener('change', (e) => send('dryer.set', { dryer: currentDryer(), on: e.target.checked }));
$('dryer-temp').addEventListener('input', (e) => {
  $('dryer-temp-out').textContent = e.target.value;
  send('dryer.set', { dryer: currentDryer(), temperature: Number(e.target.value) });
});
$('dryer-speed').addEventListener('input', (e) => {
  $('dryer-speed-out').textContent = Number(e.target.value).toFixed(1);
  send('dryer.set', { dryer: currentDryer(), speed: Number(e.target.value) });
});

$('lamp').addEventListener('change', showLamp);
$('lamp-on').addEventListener('change', (e) => send('lamp.set', { lamp: currentLamp(), on: e.target.checked }));
$('lamp-temp').addEventListener('input', (e) => {
  $('lamp-temp-out').textContent = e.target.value;
  send('lamp.set', { lamp: currentLamp(), temperature: Number(e.target.value) });
});

$('emitter').addEventListener('change', showEmitter);
$('emitter-open').addEventListener('change', (e) => send('emitter.set', { emitter: currentEmitter(), open: e.target.checked }));
$('emitter-rate').addEventListener('input', (e) => {
  $('emitter-rate-out').textContent = Number(e.target.value).toFixed(3);
  send('emitter.set', { emitter: currentEmitter(), rate: Number(e.target.value) });
});
$('emitter-temp').addEventListener('change', (e) => {
  // A change of temperature may rebuild the solver (a run without heat), so it goes on release.
  $('emitter-temp-out').textContent = e.target.value;
  send('emitter.set', { emitter: currentEmitter(), temperature: Number(e.target.value) });
});

const sendView = () =>
  send('view.set', {
    view: $('view-kind').value,
    colour_by: $('colour-by').value,
    tint_reference: Number($('tint-reference').value),
  });
$('view-kind').addEventListener('change', sendView);
$('colour-by').addEventListener('change', sendView);
$('tint-reference').addEventListener('change', sendView);
$('full-quality').addEventListener('change', (e) => send('quality.set', { surface: e.target.checked ? 'full' : 'fast' }));
$('scale').addEventListener('change', (e) => send('quality.set', { scale: Number(e.target.value) }));

connect();
