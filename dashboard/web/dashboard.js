// tomorig dashboard: one page, fed by the server's event stream (/events), drawing its gauges,
// histograms, profile and time series itself on canvases. No library, nothing fetched from
// elsewhere. Topics and fields: docs/dashboard.md and docs/wire-protocol.md.
'use strict';

const token = new URLSearchParams(location.search).get('token');
const withToken = (path) =>
  token ? path + (path.includes('?') ? '&' : '?') + 'token=' + encodeURIComponent(token) : path;
const $ = (id) => document.getElementById(id);
const FLAG_COLOUR = { green: '#2e9d4a', amber: '#e0a100', red: '#d33a2c' };

const state = { info: null, quicklook: null, preview: null, status: null, alarms: { acknowledged: [] }, history: null };
let paused = false;
const LIVE_TOPICS = ['quicklook', 'preview', 'status'];

// ---- small helpers -----------------------------------------------------------------------------

function el(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (k === 'class') e.className = v; else e.setAttribute(k, v);
  }
  for (const c of children) e.append(c);
  return e;
}
const num = (v) => (typeof v === 'number' && isFinite(v) ? v : null);
function fmt(v, digits = 3, unit = '') {
  const n = num(v);
  return n === null ? '–' : n.toFixed(digits) + unit;
}
const judgedValue = (j) => (j && typeof j === 'object' ? num(j.value) : null);
const judgedFlag = (j) => (j && typeof j === 'object' && j.flag ? j.flag : 'red');
function setPill(node, flag, text) {
  node.className = 'pill ' + (flag || '');
  node.textContent = text;
}
function fill(dl, rows) {
  dl.replaceChildren(...rows.flatMap(([k, v, cls]) => [el('dt', {}, k), el('dd', cls ? { class: cls } : {}, v)]));
}
// A canvas drawn at its displayed size, so lines stay sharp.
function context2d(canvas) {
  const w = Math.max(1, Math.round(canvas.clientWidth || canvas.width));
  const h = Math.max(1, Math.round(canvas.clientHeight || canvas.height));
  if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
  const g = canvas.getContext('2d');
  g.clearRect(0, 0, w, h);
  return { g, w, h };
}

// ---- gauges: the value against its green range and amber band ---------------------------------

function drawGauge(canvas, value, target, flag) {
  const { g, w, h } = context2d(canvas);
  if (!target) return;
  const amberLow = target.low / (1 + target.amber), amberHigh = target.high * (1 + target.amber);
  const top = amberHigh * 1.3;
  const x = (v) => Math.max(0, Math.min(w, (v / top) * w));
  g.fillStyle = FLAG_COLOUR.red; g.fillRect(0, 0, w, h);
  g.fillStyle = FLAG_COLOUR.amber; g.fillRect(x(amberLow), 0, x(amberHigh) - x(amberLow), h);
  g.fillStyle = FLAG_COLOUR.green; g.fillRect(x(target.low), 0, x(target.high) - x(target.low), h);
  g.globalAlpha = 0.55; g.fillStyle = '#000'; g.fillRect(0, 0, w, h); g.globalAlpha = 1;
  if (value !== null) {
    g.fillStyle = FLAG_COLOUR[flag] || '#fff';
    g.fillRect(0, h * 0.3, x(value), h * 0.4);
    g.fillStyle = '#fff';
    g.fillRect(Math.min(w - 2, x(value)), 0, 2, h);
  }
}

function gaugeRow(label, key) {
  const canvas = el('canvas', { height: '12' });
  const value = el('span', { class: 'value' }, '–');
  const row = el('div', { class: 'gauge', 'data-figure': key }, el('span', {}, label), canvas, value);
  return { row, canvas, value };
}

// ---- histogram: log counts over [0, full scale], the saturated bin in red -----------------------

function drawHistogram(canvas, histogram, saturated) {
  const { g, w, h } = context2d(canvas);
  g.fillStyle = '#0b0d10'; g.fillRect(0, 0, w, h);
  const counts = histogram && Array.isArray(histogram.counts) ? histogram.counts : [];
  if (!counts.length) return;
  const top = Math.log10(1 + Math.max(...counts));
  const bw = w / counts.length;
  counts.forEach((c, i) => {
    const bar = top > 0 ? (Math.log10(1 + c) / top) * (h - 2) : 0;
    g.fillStyle = i === counts.length - 1 ? (c > 0 ? FLAG_COLOUR.red : '#553') : '#9fb4cc';
    g.fillRect(i * bw, h - bar, Math.max(1, bw - 0.2), bar);
  });
  g.fillStyle = '#ccc'; g.font = '10px sans-serif';
  g.fillText('saturated ' + fmt(saturated === null ? null : saturated * 100, 3, ' %'), 4, 11);
}

// ---- camera tiles --------------------------------------------------------------------------------

const tiles = new Map();
const FIGURES = [
  ['ppp', 'ppp', (s) => s.a && s.a.particles && s.a.particles.ppp, 4],
  ['d_τ px', 'diameter_px', (s) => s.a && s.a.particles && s.a.particles.diameter_px, 2],
  ['Ns', 'source_density', (s) => s.a && s.a.particles && s.a.particles.source_density, 3],
  ['B/A', 'energy_balance', (s) => s.energy_balance, 2],
];
const DT_FIGURES = [
  ['Δt px', 'dt_displacement_px', (d) => d.displacement_px, 1],
  ['Δt valid', 'dt_valid_fraction', (d) => d.valid_fraction, 2],
];

function tileFor(id) {
  if (tiles.has(id)) return tiles.get(id);
  const head = el('div', { class: 'tile-head' }, el('span', {}, id), el('span', { class: 'health' }, '–'));
  const thumb = el('img', { class: 'thumb', alt: id + ' frame A' });
  const histogram = el('canvas', { class: 'histogram', height: '60' });
  const gauges = {};
  const body = el('div', { class: 'tile-body' }, thumb, histogram);
  for (const [label, key] of [...FIGURES, ...DT_FIGURES]) {
    gauges[key] = gaugeRow(label, key);
    body.append(gauges[key].row);
  }
  const lost = el('div', { class: 'reason lost' }, '');
  const reason = el('div', { class: 'reason why' }, '');
  body.append(lost, reason);
  const node = el('div', { class: 'tile', 'data-camera': id }, head, body);
  $('cameras').append(node);
  const tile = { node, head, thumb, histogram, gauges, lost, reason, shownSet: null };
  tiles.set(id, tile);
  return tile;
}

// The tile's colour is the camera's health: red when it is disconnected or its frame is missing,
// amber once it has lost frames, green otherwise. The figures carry their own flags.
function cameraHealth(id) {
  const cam = state.status && (state.status.cameras || []).find((c) => c.id === id);
  const ql = state.quicklook && (state.quicklook.cameras || []).find((c) => c.id === id);
  if (cam && cam.connected === false) return ['red', 'disconnected: ' + (cam.problem || 'no reason given')];
  if (ql && ql.statistics === null && !ql.shadow) return ['red', 'frame missing' + (ql.missing ? ': ' + ql.missing : '')];
  if (cam && cam.frames_lost > 0) return ['amber', cam.frames_lost + ' frames lost'];
  if (!cam && !ql) return ['', 'no data'];
  return ['green', 'ok'];
}

function renderTileHealth(id) {
  const tile = tileFor(id);
  const [colour, text] = cameraHealth(id);
  tile.node.className = 'tile ' + colour;
  tile.head.querySelector('.health').textContent = text;
  const cam = state.status && (state.status.cameras || []).find((c) => c.id === id);
  tile.lost.textContent = cam ? `frames ${cam.frames}, lost ${cam.frames_lost}, incomplete sets ${cam.incomplete_sets}` : '';
}

// A shadowgraphy rig's camera (the quick-look's shadow mode, docs/spray.md): its spray figures
// and LED alarms in one line, as the particle gauges have nothing to show.
function shadowSummary(sh) {
  const a = sh.a || {};
  const bright = a.bright_field ? num(a.bright_field.level) : null;
  const shadows = a.shadows ? a.shadows.count : null;
  const text = `bright ${fmt(bright, 0)} counts, ${shadows === null ? '-' : shadows} shadows, ` +
    `LED B/A ${fmt(judgedValue(sh.energy_ratio), 2)} (${judgedFlag(sh.energy_ratio)})`;
  const alarms = sh.led_energy_alarms || [];
  return alarms.length ? text + ': ' + alarms.join('; ') : text;
}

function renderQuickLook() {
  const q = state.quicklook;
  if (!q) return;
  $('set').textContent = q.set;
  setPill($('set-flag'), q.flag, q.flag);
  const targets = (state.info && state.info.targets) || {};
  const images = new Set((q.images || []).map((i) => i.name));
  for (const cam of q.cameras || []) {
    const tile = tileFor(cam.id);
    if (images.has(cam.id + '/a')) tile.thumb.src = withToken(`/image/${cam.id}/a?set=${q.set}`);
    const s = cam.statistics;
    tile.thumb.classList.toggle('stale', !s && !cam.shadow);  // the frame is missing: the picture is an older one
    drawHistogram(tile.histogram, s && s.a ? s.a.histogram : null,
      s && s.a && s.a.saturation ? judgedValue(s.a.saturation.fraction) : null);
    for (const [, key, pick, digits] of FIGURES) {
      const j = s ? pick(s) : null;
      const gauge = tile.gauges[key];
      drawGauge(gauge.canvas, judgedValue(j), targets[key], judgedFlag(j));
      gauge.value.textContent = fmt(judgedValue(j), digits);
      gauge.value.className = 'value ' + judgedFlag(j) + '-text';
    }
    for (const [, key, pick, digits] of DT_FIGURES) {
      const j = cam.dt_check ? pick(cam.dt_check) : null;
      const gauge = tile.gauges[key];
      drawGauge(gauge.canvas, judgedValue(j), targets[key], judgedFlag(j));
      gauge.value.textContent = fmt(judgedValue(j), digits);
      gauge.value.className = 'value ' + judgedFlag(j) + '-text';
    }
    tile.reason.textContent = cam.shadow ? shadowSummary(cam.shadow)
      : cam.statistics === null ? 'not measured: ' + (cam.missing || '') : '';
    tile.shownSet = q.set;
    renderTileHealth(cam.id);
  }
  // Δt: the pulse separation the set was taken with against the trigger plan's.
  const plan = state.info && state.info.trigger_plan;
  const dtUs = num(q.dt_ns) === null ? null : q.dt_ns / 1000;
  if (plan && num(plan.dt_us) !== null && dtUs !== null) {
    const ok = Math.abs(dtUs - plan.dt_us) <= 0.01 * plan.dt_us;
    setPill($('dt-check'), ok ? 'green' : 'red', `Δt ${fmt(dtUs, 1)} µs (plan ${fmt(plan.dt_us, 1)})`);
  } else {
    setPill($('dt-check'), '', `Δt ${fmt(dtUs, 1)} µs`);
  }
  renderDrift(q.drift);
  renderAlarms();
}

// ---- preview volume -----------------------------------------------------------------------------

function drawProfile(canvas, sheet) {
  const { g, w, h } = context2d(canvas);
  g.fillStyle = '#0b0d10'; g.fillRect(0, 0, w, h);
  const profile = sheet && Array.isArray(sheet.profile) ? sheet.profile : [];
  if (!profile.length) return;
  const bw = w / profile.length;
  profile.forEach((v, i) => {
    if (num(v) === null) return;
    const bar = Math.max(0, Math.min(1, v)) * (h - 14);
    g.fillStyle = '#9fb4cc';
    g.fillRect(i * bw, h - bar, Math.max(1, bw - 0.3), bar);
  });
  const z0 = num(sheet.z0_mm), dz = num(sheet.dz_mm);
  g.strokeStyle = FLAG_COLOUR[sheet.flag] || '#fff';
  g.setLineDash([4, 3]);
  for (const edge of [sheet.low_edge_mm, sheet.high_edge_mm]) {
    if (num(edge) === null || z0 === null || !dz) continue;
    const x = ((edge - z0) / dz + 0.5) * bw;
    g.beginPath(); g.moveTo(x, 0); g.lineTo(x, h); g.stroke();
  }
  g.setLineDash([]);
  g.fillStyle = '#ccc'; g.font = '10px sans-serif';
  g.fillText('depth profile: mean intensity per z slice (sheet edges dashed)', 4, 11);
}

function renderPreview() {
  const p = state.preview;
  if (!p) return;
  const names = new Set((p.images || []).map((i) => i.name));
  for (const name of ['mip_z', 'mip_y', 'mip_x'])
    if (names.has(name)) $(name).src = withToken(`/image/${name}?set=${p.set}`);
  const sheet = (p.preview && p.preview.sheet) || {};
  $('preview-set').textContent = `of set ${p.set}, ${fmt(p.latency_s, 2)} s after it`;
  drawProfile($('profile'), sheet);
  fill($('sheet'), [
    ['sheet', sheet.found ? `at ${fmt(sheet.position_mm, 3)} mm, ${fmt(sheet.thickness_mm, 3)} mm thick` : 'not found',
      (sheet.flag || 'red') + '-text'],
    ['ghost level', `${fmt(sheet.ghost_front, 2)} front / ${fmt(sheet.ghost_back, 2)} back`],
    ['RSNR', fmt(sheet.rsnr, 1)],
    ['active voxels', p.preview && p.preview.active_voxels !== undefined ? String(p.preview.active_voxels) : '–'],
  ]);
}

// ---- drift and alarms ---------------------------------------------------------------------------

function renderDrift(drift) {
  if (!drift) {
    setPill($('drift-flag'), '', 'waiting');
    fill($('drift'), [['monitor', 'no report yet (needs the preview volume and ≥ 3 sets)']]);
    return;
  }
  setPill($('drift-flag'), drift.flag, drift.flag);
  const ids = (state.quicklook && state.quicklook.cameras || []).map((c) => c.id);
  const warn = state.info && state.info.targets ? state.info.targets.drift_warn_px : null;
  fill($('drift'), [
    ['sets pooled', String(drift.sets)],
    ...(drift.largest_px || []).map((v, i) => [
      `${ids[i] || 'camera ' + i} largest`, fmt(v, 2, ' px'),
      num(v) !== null && warn !== null && v > warn ? 'red-text' : '']),
    ['alarms', String((drift.alarms || []).length)],
  ]);
}

function currentAlarms() {
  const alarms = [];
  const q = state.quicklook;
  for (const text of (q && q.drift && q.drift.alarms) || [])
    alarms.push({ key: 'drift:' + String(text).split(' ')[0], text: 'Drift: ' + text });
  for (const cam of (state.status && state.status.cameras) || [])
    if (cam.connected === false)
      alarms.push({ key: 'camera:' + cam.id, text: `Camera ${cam.id} disconnected: ${cam.problem || ''}` });
  const seen = new Set();
  return alarms.filter((a) => !seen.has(a.key) && seen.add(a.key));
}

function renderAlarms() {
  const acknowledged = new Set(state.alarms.acknowledged || []);
  $('alarms').replaceChildren(...currentAlarms().map((a) => {
    const done = acknowledged.has(a.key);
    const button = el('button', { type: 'button' }, done ? 'Acknowledged' : 'Acknowledge');
    button.disabled = done;
    button.addEventListener('click', () => acknowledge(a.key));
    return el('div', { class: 'alarm' + (done ? ' acknowledged' : ''), 'data-alarm': a.key }, el('span', {}, a.text), button);
  }));
}

async function acknowledge(key) {
  const r = await fetch(withToken('/api/ack'), {
    method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify({ key }) });
  if (r.ok) { state.alarms = await r.json(); renderAlarms(); }
}

// ---- rig status ---------------------------------------------------------------------------------

function renderStatus() {
  const s = state.status;
  if (!s) return;
  const gb = (b) => (num(b) === null || b < 0 ? 'not recording' : (b / 1e9).toFixed(1) + ' GB');
  fill($('status'), [
    ['state', s.state, s.state === 'failed' ? 'red-text' : s.state === 'running' ? 'green-text' : 'amber-text'],
    ['sets', String(s.sets_total)],
    ['rate', `${fmt(s.sets_per_second, 1)} sets/s`],
    ['stream', `${fmt(s.stream_mb_per_second, 1)} MB/s`],
    ['to disk', `${fmt(s.disk_mb_per_second, 1)} MB/s`],
    ['disk left', gb(s.disk_free_bytes) + (num(s.disk_minutes_until_full) !== null && s.disk_minutes_until_full >= 0
      ? `, full in ${fmt(s.disk_minutes_until_full, 0)} min` : ''),
      s.disk_minutes_until_full >= 0 && s.disk_minutes_until_full < 10 ? 'red-text' : ''],
    ['frames lost', String(s.frames_lost), s.frames_lost > 0 ? 'amber-text' : ''],
    ['incomplete sets', String(s.incomplete_sets), s.incomplete_sets > 0 ? 'amber-text' : ''],
    ['queue', `${s.queue_depth} sets`],
    ['trigger lag', `${s.trigger_lag_events} events (${fmt(s.trigger_lag_ms, 0)} ms), ${s.dropped_trigger_events} dropped`,
      s.dropped_trigger_events > 0 ? 'red-text' : ''],
    ['preview drops', String(s.preview_drops)],
  ]);
  $('warnings').replaceChildren(...(s.warnings || []).map((w) => el('li', {}, w)));
  for (const cam of s.cameras || []) renderTileHealth(cam.id);
  renderAlarms();
}

// ---- info: source, trigger plan, snapshots ------------------------------------------------------

function renderInfo() {
  const i = state.info;
  if (!i) return;
  $('source').textContent = (i.mode === 'session' ? 'session ' : 'live: ') + (i.source || '');
  const plan = i.trigger_plan;
  $('plan').textContent = plan ? plan.text || plan.error || '' : 'not known to this dashboard (tomorig preview --config RIG shows it)';
  $('snapshot').disabled = !i.snapshots;
  if (!i.snapshots) $('snapshot').title = 'Snapshots are off: start the dashboard with --snapshots FOLDER';
  if (i.mode === 'session') {
    document.body.classList.add('session');
    $('pause').disabled = true;
    setPill($('connection'), 'green', 'recorded');
  }
}

// ---- session history: time series ---------------------------------------------------------------

const SERIES_COLOURS = ['#6cb4ff', '#ffb36c', '#8de28d', '#e98de2', '#f2e36b', '#8de2d9'];

function drawChart(canvas, series, band) {
  const { g, w, h } = context2d(canvas);
  const pad = { l: 46, r: 8, t: 8, b: 18 };
  const points = series.flatMap((s) => s.points);
  if (!points.length) { g.fillStyle = '#888'; g.fillText('not measured', pad.l, h / 2); return; }
  let [x0, x1] = [Math.min(...points.map((p) => p[0])), Math.max(...points.map((p) => p[0]))];
  let [y0, y1] = [Math.min(...points.map((p) => p[1])), Math.max(...points.map((p) => p[1]))];
  if (band) { y0 = Math.min(y0, band[0]); y1 = Math.max(y1, band[1]); }
  if (x1 === x0) x1 = x0 + 1;
  if (y1 === y0) { y0 -= 0.5 * Math.abs(y0 || 1); y1 += 0.5 * Math.abs(y1 || 1); }
  const X = (x) => pad.l + ((x - x0) / (x1 - x0)) * (w - pad.l - pad.r);
  const Y = (y) => h - pad.b - ((y - y0) / (y1 - y0)) * (h - pad.t - pad.b);
  if (band) {
    g.fillStyle = 'rgba(46,157,74,0.18)';
    g.fillRect(pad.l, Y(band[1]), w - pad.l - pad.r, Y(band[0]) - Y(band[1]));
  }
  g.strokeStyle = '#444'; g.strokeRect(pad.l, pad.t, w - pad.l - pad.r, h - pad.t - pad.b);
  g.fillStyle = '#aaa'; g.font = '10px sans-serif';
  g.fillText(y1.toPrecision(3), 2, pad.t + 8); g.fillText(y0.toPrecision(3), 2, h - pad.b);
  g.fillText('set ' + x0, pad.l, h - 4); g.fillText('set ' + x1, w - pad.r - 40, h - 4);
  series.forEach((s, k) => {
    g.strokeStyle = SERIES_COLOURS[k % SERIES_COLOURS.length];
    g.beginPath();
    s.points.forEach(([x, y], i) => (i ? g.lineTo(X(x), Y(y)) : g.moveTo(X(x), Y(y))));
    g.stroke();
    g.fillStyle = g.strokeStyle;
    g.fillText(s.name, pad.l + 6 + k * 52, pad.t + 10);
  });
}

function renderHistory() {
  const hist = state.history;
  if (!hist) return;
  $('history-panel').classList.remove('hidden');
  $('history-range').textContent = `${hist.sets} sets measured (${hist.first_set}–${hist.last_set}), ` +
    `${hist.previews} preview volumes, ${hist.drift_alarm_sets} sets with drift alarms`;
  const rows = (hist.history || []).slice().sort((a, b) => a.set - b.set);
  const ids = (hist.cameras || []).map((c) => c.id);
  const targets = (state.info && state.info.targets) || {};
  const perCamera = (pick) => ids.map((id, c) => ({
    name: id,
    points: rows.map((r) => [r.set, r.cameras && r.cameras[c] ? pick(r.cameras[c]) : null]).filter((p) => num(p[1]) !== null),
  }));
  const perSet = (name, pick) => [{ name, points: rows.map((r) => [r.set, pick(r)]).filter((p) => num(p[1]) !== null) }];
  const band = (t) => (t ? [t.low, t.high] : null);
  const charts = [
    ['ppp (frame A)', perCamera((c) => c.ppp[0]), band(targets.ppp)],
    ['particle image diameter d_τ (px)', perCamera((c) => c.diameter_px[0]), band(targets.diameter_px)],
    ['saturated fraction (larger of A, B)', perCamera((c) => {
      const both = c.saturated_fraction.map(num).filter((v) => v !== null);
      return both.length ? Math.max(...both) : null;
    }), band(targets.saturated_fraction)],
    ['Δt check displacement (px)', perCamera((c) => c.dt_displacement_px), band(targets.dt_displacement_px)],
    ['drift, largest sub-volume (px)', perCamera((c) => c.drift_px), targets.drift_warn_px ? [0, targets.drift_warn_px] : null],
    ['sheet position (mm)', perSet('position', (r) => r.sheet_position_mm), null],
    ['sheet thickness (mm)', perSet('thickness', (r) => r.sheet_thickness_mm), null],
    ['RSNR', perSet('RSNR', (r) => r.rsnr), null],
    ['drift alarms', perSet('alarms', (r) => r.drift_alarms), null],
  ];
  const box = $('history');
  if (box.children.length !== charts.length)
    box.replaceChildren(...charts.map(([title]) => el('div', { class: 'chart' }, el('h3', {}, title), el('canvas', { height: '160' }))));
  charts.forEach(([, series, b], i) => drawChart(box.children[i].querySelector('canvas'), series, b));
}

// ---- the event stream ---------------------------------------------------------------------------

const RENDER = { info: renderInfo, quicklook: renderQuickLook, preview: renderPreview, status: renderStatus,
  alarms: renderAlarms, history: renderHistory };

function connect() {
  const events = new EventSource(withToken('/events'));
  events.onopen = () => {
    if (!state.info || state.info.mode !== 'session') setPill($('connection'), 'green', 'live');
  };
  events.onerror = () => setPill($('connection'), 'red', 'disconnected, retrying');
  // The run (or the viewer) ended: what is shown stays, nothing more will come.
  events.addEventListener('end', () => {
    events.close();
    setPill($('connection'), 'amber', 'ended');
  });
  for (const topic of Object.keys(RENDER)) {
    events.addEventListener(topic, (e) => {
      state[topic] = JSON.parse(e.data);
      if (paused && LIVE_TOPICS.includes(topic)) return;  // kept, drawn on resume
      RENDER[topic]();
    });
  }
}

$('pause').addEventListener('click', () => {
  paused = !paused;
  document.body.classList.toggle('paused', paused);
  $('pause').textContent = paused ? 'Resume' : 'Pause';
  $('pause').classList.toggle('on', paused);
  if (!paused) for (const topic of LIVE_TOPICS) RENDER[topic]();
});

$('snapshot').addEventListener('click', async () => {
  const r = await fetch(withToken('/api/snapshot'), { method: 'POST' });
  const body = await r.json();
  $('action-result').textContent = r.ok ? 'snapshot: ' + body.file : body.error;
});

window.addEventListener('resize', () => { for (const t of Object.keys(RENDER)) if (state[t]) RENDER[t](); });
connect();
