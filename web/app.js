// The thaw browser client: one WebSocket (subprotocol thaw.v1, docs/PROTOCOL.md) carrying JSON events
// and binary frames (a 28-byte header, then JPEG). Every frame is acknowledged, so the server never
// sends more than it can take; controls are protocol commands.
'use strict';

const $ = (id) => document.getElementById(id);
const canvas = $('view');
const ctx = canvas.getContext('2d');
const plot = $('plot');
const hud = $('hud');

let ws = null;
let nextId = 1;
let welcome = null;
let paused = false;
let dryers = [];          // the scene's dryers as the server last described them
let emitters = [];        // and its taps (emitters), with their flow in L/s
let history = [];         // [sim time, ice fraction, mean temperature]
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

function onEvent(m) {
  switch (m.type) {
    case 'welcome':
      welcome = m;
      $('scene-name').textContent = m.scene;
      $('role').textContent = m.role === 'controller' ? '' : '(viewer: controls are off)';
      // The frame is shared by every viewer, so only a controller sets its size and quality.
      if (m.role === 'controller') send('quality.set', { width: canvas.width, height: canvas.height });
      $('full-quality').disabled = m.role !== 'controller';
      fillSelect($('scene'), m.scenes || [], m.scene);
      dryers = m.dryers || [];
      $('dryers').hidden = dryers.length === 0;
      fillSelect($('dryer'), dryers.map((_, i) => String(i)), '0');
      showDryer();
      emitters = m.emitters || [];
      $('taps').hidden = emitters.length === 0;
      fillSelect($('emitter'), emitters.map((_, i) => String(i)), '0');
      showEmitter();
      history = [];
      break;
    case 'stats':
      paused = !!m.paused;
      $('pause').textContent = paused ? 'Resume' : 'Pause';
      if (m.dryers) dryers = m.dryers;
      if (m.emitters) {
        const changed = m.emitters.length !== emitters.length;
        emitters = m.emitters;
        $('taps').hidden = emitters.length === 0;
        if (changed) fillSelect($('emitter'), emitters.map((_, i) => String(i)), '0');
        showEmitter();
      }
      history.push([m.time, m.ice_fraction, m.temperature.mean]);
      if (history.length > 2000) history.splice(0, history.length - 2000);
      hud.textContent =
        `t ${m.time.toFixed(3)} s   ${m.steps_per_second.toFixed(0)} steps/s   ${fps.toFixed(1)} fps\n` +
        `ice ${(1000 * m.ice_mass).toFixed(2)} g (${(100 * m.ice_fraction).toFixed(1)} %)   ` +
        `T mean ${m.temperature.mean.toFixed(2)} °C max ${m.temperature.max.toFixed(1)} °C\n` +
        `particles ${m.particles.water} water, ${m.particles.ice} ice   ` +
        (m.inflow ? `poured ${(1000 * m.inflow.mass).toFixed(1)} g   ` : '') +
        (m.outflow ? `ran out ${(1000 * m.outflow.mass).toFixed(1)} g   ` : '') +
        `energy closure ${m.energy.closure_relative.toExponential(1)}` + (m.error ? `\nstopped: ${m.error}` : '');
      drawPlot();
      break;
    case 'error':
      $('message').textContent = `${m.of || ''} ${m.code}: ${m.message}`;
      break;
    case 'ack':
      $('message').textContent = '';
      if (m.of === 'scene.load' || m.of === 'sim.reset' || m.of === 'state.load') history = [];
      break;
  }
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

function currentDryer() {
  return Number($('dryer').value || 0);
}

function showDryer() {
  const d = dryers[currentDryer()];
  if (!d) return;
  $('dryer-on').checked = d.on;
  $('dryer-temp').value = d.temperature;
  $('dryer-speed').value = d.speed;
  $('dryer-temp-out').textContent = d.temperature;
  $('dryer-speed-out').textContent = d.speed;
}

function currentEmitter() {
  return Number($('emitter').value || 0);
}

// The tap's controls follow the server, except the slider a user is dragging.
function showEmitter() {
  const e = emitters[currentEmitter()];
  if (!e) return;
  $('emitter-open').checked = e.open;
  if (document.activeElement !== $('emitter-rate')) $('emitter-rate').value = e.rate;
  if (document.activeElement !== $('emitter-temp')) $('emitter-temp').value = e.temperature;
  $('emitter-rate-out').textContent = Number(e.rate).toFixed(3);
  $('emitter-temp-out').textContent = Number(e.temperature).toFixed(0);
}

function drawPlot() {
  const g = plot.getContext('2d');
  g.clearRect(0, 0, plot.width, plot.height);
  if (history.length < 2) return;
  const t0 = history[0][0], t1 = history[history.length - 1][0] || 1;
  const temps = history.map((h) => h[2]);
  const lo = Math.min(...temps), hi = Math.max(...temps) + 1e-9;
  const x = (t) => ((t - t0) / (t1 - t0 || 1)) * (plot.width - 10) + 5;
  const line = (value, colour) => {
    g.strokeStyle = colour;
    g.beginPath();
    history.forEach((h, i) => {
      const y = plot.height - 5 - value(h) * (plot.height - 10);
      i ? g.lineTo(x(h[0]), y) : g.moveTo(x(h[0]), y);
    });
    g.stroke();
  };
  line((h) => h[1], '#9fd8ff');                      // ice fraction of the start, 0..1
  line((h) => (h[2] - lo) / (hi - lo), '#ff9f6b');   // mean temperature, scaled to its range
  g.fillStyle = '#9fd8ff';
  g.fillText('ice fraction', 8, 12);
  g.fillStyle = '#ff9f6b';
  g.fillText(`mean T ${lo.toFixed(1)}–${hi.toFixed(1)} °C`, 90, 12);
}

// Orbit by dragging, zoom by the wheel; with "aim" ticked, a click or drag aims the dryer at the surface
// under the pointer (the server picks it from the same field it renders).
let drag = null;
canvas.addEventListener('pointerdown', (e) => {
  drag = { x: e.offsetX, y: e.offsetY };
  canvas.setPointerCapture(e.pointerId);
  if ($('aim').checked) aimAt(e);
});
canvas.addEventListener('pointermove', (e) => {
  if (!drag) return;
  if ($('aim').checked) {
    aimAt(e);
    return;
  }
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

$('aim').addEventListener('change', () => canvas.classList.toggle('aiming', $('aim').checked));
$('pause').addEventListener('click', () => send(paused ? 'sim.resume' : 'sim.pause'));
$('step').addEventListener('click', () => send('sim.step', { n: 10 }));
$('reset').addEventListener('click', () => send('sim.reset'));
$('scene').addEventListener('change', (e) => send('scene.load', { name: e.target.value }));
$('dryer').addEventListener('change', showDryer);
$('dryer-on').addEventListener('change', (e) => send('dryer.set', { dryer: currentDryer(), on: e.target.checked }));
$('dryer-temp').addEventListener('input', (e) => {
  $('dryer-temp-out').textContent = e.target.value;
  send('dryer.set', { dryer: currentDryer(), temperature: Number(e.target.value) });
});
$('dryer-speed').addEventListener('input', (e) => {
  $('dryer-speed-out').textContent = e.target.value;
  send('dryer.set', { dryer: currentDryer(), speed: Number(e.target.value) });
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
const sendView = () => send('view.set', { view: $('view-kind').value, colour_by: $('colour-by').value });
$('view-kind').addEventListener('change', sendView);
$('full-quality').addEventListener('change', (e) => send('quality.set', { surface: e.target.checked ? 'full' : 'fast' }));
$('colour-by').addEventListener('change', sendView);

connect();
