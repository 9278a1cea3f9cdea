// The eamos monitor page: one clock for the map, the lanes, the graph and the mission text.
// Everything comes from the server's WebSocket (/ws): first the mission, then the trace
// events (the history so far, then each new one). The page sends nothing that matters: the
// monitor cannot command a drone. Text from the trace is only ever set as textContent.
'use strict';

const STATE_FILL = {
  waiting: '#fff59d', running: '#90caf9', succeeded: '#a5d6a7', failed: '#ef9a9a', preempted: '#ffcc80',
  cancelled: '#bdbdbd', released: '#b2ebf2', true: '#a5d6a7', false: '#cfd8dc', 'not-run': '#f5f5f5',
};
const DOM_LANES_MAX = 60;  // more drones: lanes on a canvas, no element per bar

const S = {
  mission: null, live: false, finished: false, events: [], clock: 0, playing: false, speed: 1,
  follow: true, selected: null, dirty: true, structureDirty: true, itemsDirty: true, graphIndex: 0,
  liveFrom: Infinity, undrawn: [], latencies: [], arrivals: [], serverDelays: [], renderTimes: [],
  laneColumns: { renders: 0, drawn: 0, columns: 0 },
};
const LATENCIES_MAX = 200000;  // the newest this many; enough for any percentile worth asking

// The wall clock (Unix ms, sub-ms), comparable with the stamps eamos puts beside live events.
function wallNow() { return performance.timeOrigin + performance.now(); }
let D = null;  // what the events say, rebuilt incrementally (see resetDerived)

function $(id) { return document.getElementById(id); }
function el(tag, cls, text) {
  const e = document.createElement(tag);
  if (cls) e.className = cls;
  if (text !== undefined) e.textContent = text;
  return e;
}
function num(v, fallback) { return typeof v === 'number' && isFinite(v) ? v : fallback; }
function str(v) { return typeof v === 'string' ? v : ''; }

function resetDerived() {
  D = {
    drones: [], droneIndex: new Map(), bars: [], barsEnded: 0, openBars: new Map(), conds: [], telemetry: new Map(),
    messages: [], nodeHistory: new Map(), end: 0, outcome: '', failures: [], eventTimes: [], violations: [],
    nodeKey: new Map(), nodes: new Map(), lastIngested: 0, missionReason: '', missionT: null, failMarks: [],
    waitSpans: new Map(), giveWays: [],
    // Where the telemetry has been so far, kept as it comes: a frame must not walk every
    // sample of a thousand drones to scale the map.
    seen: { minX: Infinity, maxX: -Infinity, minY: Infinity, maxY: -Infinity, maxZ: 1 },
  };
  S.mapBounds = null;  // a new mission: the map and its tracks' layer start again
  S.trails = null;
  const m = S.mission || {};
  for (const d of Array.isArray(m.drones) ? m.drones : []) addDrone(str(d.name), d);
  for (const n of Array.isArray(m.nodes) ? m.nodes : []) {
    D.nodes.set(n.id, n);
    const key = str(n.drone) + '|' + n.line + '|' + str(n.name);
    if (!D.nodeKey.has(key)) D.nodeKey.set(key, []);
    D.nodeKey.get(key).push(n.id);
  }
}

function addDrone(name, info) {
  if (!name || D.droneIndex.has(name)) return D.droneIndex.get(name);
  const i = D.drones.length;
  const home = info && Array.isArray(info.home) ? info.home.map(v => num(v, 0)) : null;
  const geofence = info ? info.geofence : null;
  const fenceKey = geofence && Array.isArray(geofence.polygon) && geofence.polygon.length > 2 ?
    JSON.stringify(geofence.polygon) : '';  // the fleet's drones share one fence: drawn once
  D.drones.push({ name, index: i, home, geofence, fenceKey, colour: droneColour(i) });
  D.droneIndex.set(name, i);
  S.structureDirty = true;
  return i;
}

// Drone i's colour in every picture of eamos: the server sends the palette (graph/palette.h)
// with the mission, so the page and the SVGs cannot disagree.
function droneColour(i) {
  const p = S.mission && Array.isArray(S.mission.palette) ? S.mission.palette : [];
  const c = p.length ? p[i % p.length] : null;
  return typeof c === 'string' && /^#[0-9A-Fa-f]{6}$/.test(c) ? c : '#555555';
}

// The MEG nodes an event is about: its "node" field, else (older traces) drone + line + name.
function nodesOf(e) {
  if (Number.isInteger(e.node)) return [e.node];
  return D.nodeKey.get(str(e.drone) + '|' + e.line + '|' + str(e.name)) || [];
}

function nodeState(e) {
  if (e.event === 'start') return 'running';
  if (e.event === 'end') return str(e.outcome) || 'succeeded';
  if (e.event === 'condition') {
    if (str(e.name).startsWith('Wait') && e.value === false) return 'waiting';
    return e.value ? 'true' : 'false';
  }
  if (e.event === 'released' || e.event === 'cancelled') return e.event;
  return null;
}

function ingest(e) {
  if (!e || typeof e !== 'object' || typeof e.t !== 'number' || typeof e.event !== 'string') return;
  const t = e.t;
  D.end = Math.max(D.end, t);
  // "Next event" steps through the mission's story, not through telemetry samples,
  // messages or graph-node bookkeeping.
  if (['start', 'end', 'condition', 'failsafe', 'mission', 'violation', 'give_way', 'resume'].includes(e.event))
    D.eventTimes.push(t);
  if (e.drone && e.drone !== '*' && e.event !== 'message') addDrone(str(e.drone));
  const key = str(e.drone) + '|' + str(e.name) + '|' + e.line + '|' + (e.node ?? '') + '|' + (e.instance ?? '');
  if (e.event === 'start') {
    const bar = { drone: str(e.drone), name: str(e.name), line: e.line | 0, text: str(e.text), start: t, end: null,
                  outcome: '', reason: '', nodes: nodesOf(e) };
    D.bars.push(bar);
    if (!D.openBars.has(key)) D.openBars.set(key, []);
    D.openBars.get(key).push(bar);
    S.itemsDirty = true;
  } else if (e.event === 'end') {
    const open = D.openBars.get(key);
    const bar = open && open.length ? open.pop() : null;
    if (bar) { bar.end = t; bar.outcome = str(e.outcome); bar.reason = str(e.reason); bar.changed = true; D.barsEnded++; }
    if (e.outcome === 'failed') {
      const f = { t, kind: 'action', drone: str(e.drone), name: str(e.name), text: str(e.text) || str(e.name),
                  line: e.line | 0, reason: str(e.reason), nodes: nodesOf(e) };
      D.failures.push(f);
      D.failMarks.push(f);
    }
    S.itemsDirty = true;
  } else if (e.event === 'condition') {
    D.conds.push({ drone: str(e.drone), name: str(e.name), line: e.line | 0, text: str(e.text), t, value: !!e.value,
                   nodes: nodesOf(e) });
    S.itemsDirty = true;
  } else if (e.event === 'telemetry') {
    if (!D.telemetry.has(e.drone)) D.telemetry.set(e.drone, []);
    const sample = { t, x: num(e.x, 0), y: num(e.y, 0), z: num(e.z, 0), battery: e.battery, mode: str(e.mode),
                     armed: e.armed, landed: e.landed };
    D.telemetry.get(e.drone).push(sample);
    const b = D.seen;
    b.minX = Math.min(b.minX, sample.x); b.maxX = Math.max(b.maxX, sample.x);
    b.minY = Math.min(b.minY, sample.y); b.maxY = Math.max(b.maxY, sample.y); b.maxZ = Math.max(b.maxZ, sample.z);
  } else if (e.event === 'message') {
    D.messages.push({ kind: str(e.kind), from: str(e.from), to: str(e.to), node: e.node,
                      sent: num(e.sent, t), received: num(e.received, t) });
    S.itemsDirty = true;
  } else if (e.event === 'mission') {
    D.outcome = str(e.outcome);
    D.missionReason = str(e.reason);
    D.missionT = t;
    if (D.outcome === 'failed') D.failures.push({ t, kind: 'mission', drone: '', text: 'the mission failed', line: 0,
                                                  reason: D.missionReason, nodes: [] });
  } else if (e.event === 'violation') {
    // `eamos verify --trace`: a rule the path broke, at the action responsible.
    const others = Array.isArray(e.drones) ? e.drones.map(str).filter(n => n) : [];
    D.violations.push({ drone: str(e.drone), kind: str(e.kind), line: e.line | 0, text: str(e.text), t, others,
                        x: num(e.x, NaN), y: num(e.y, NaN) });
    D.failures.push({ t, kind: 'violation', drone: str(e.drone), text: str(e.kind) + ' violation', line: e.line | 0,
                      reason: str(e.text), nodes: [] });
    S.itemsDirty = true;
  } else if (e.event === 'conflict' || e.event === 'give_way' || e.event === 'resume') {
    // Separation kept in flight (docs/faults.md): who held for whom, and when it flew on.
    D.giveWays.push({ t, event: e.event, drone: str(e.drone), other: str(e.other), distance: num(e.distance, NaN),
                      reason: str(e.reason) });
    S.itemsDirty = true;
  } else if (e.event === 'failsafe' || e.event === 'error') {
    D.failures.push({ t, kind: e.event, drone: str(e.drone), text: e.event + ' ' + str(e.name), line: e.line | 0,
                      reason: str(e.reason) || str(e.text), nodes: [] });
    S.itemsDirty = true;
  }
  if (e.event !== 'telemetry' && e.event !== 'message') {
    const state = nodeState(e);
    if (state) for (const id of nodesOf(e)) {
      if (!D.nodeHistory.has(id)) D.nodeHistory.set(id, []);
      D.nodeHistory.get(id).push({ t, state, value: e.value });
    }
  }
  S.dirty = true;
}

// ---- cross-drone triggers: the trace's message events, else the MEG's cross-drone arcs ----

function laneEndBefore(drone, t) {
  let last = 0;
  for (const b of D.bars) if (b.drone === drone && b.end !== null && b.end <= t + 1e-9 && b.end > last) last = b.end;
  return last;
}

// Whether a node's recorded state fires an arc of `branch` (an action's end fires every arc;
// a condition's value fires the arcs of its outcome).
function fires(h, branch) {
  if (h.state === 'running' || h.state === 'waiting') return false;
  if (h.state === 'true') return ['true', 'go', 'repeat', 'do', 'continue', ''].includes(branch);
  if (h.state === 'false') return ['false', 'exit', 'skip', 'done', ''].includes(branch);
  return !branch || branch === 'go';
}

function triggers() {
  const out = [];
  const fromMessages = D.messages.filter(m => m.kind === 'trigger' || m.kind === 'abort');
  if (fromMessages.length) {
    for (const m of fromMessages) {
      if (!D.droneIndex.has(m.from) || !D.droneIndex.has(m.to) || m.from === m.to) continue;
      out.push({ from: m.from, to: m.to, sent: m.sent, received: m.received, node: m.node, kind: m.kind,
                 waitFrom: laneEndBefore(m.to, m.received) });
    }
    return out;
  }
  const arcs = S.mission && Array.isArray(S.mission.arcs) ? S.mission.arcs : [];
  for (const a of arcs) {
    if (a.kind !== 'exec') continue;
    const from = D.nodes.get(a.from), to = D.nodes.get(a.to);
    if (!from || !to || !from.drone || !to.drone || from.drone === to.drone) continue;
    const fired = (D.nodeHistory.get(a.from) || []).filter(h => fires(h, a.branch));
    const started = (D.nodeHistory.get(a.to) || []).filter(h => h.state !== 'waiting');
    let next = 0;
    fired.forEach((f, i) => {
      // Each firing triggers the target's next run: the first one after it and before the next firing.
      const until = i + 1 < fired.length ? fired[i + 1].t : Infinity;
      while (next < started.length && started[next].t < f.t - 1e-9) next++;
      if (next >= started.length || started[next].t > until + 1e-9) return;
      const s = started[next++];
      out.push({ from: from.drone, to: to.drone, sent: f.t, received: s.t, node: a.from, kind: 'trigger',
                 waitFrom: laneEndBefore(to.drone, s.t) });
    });
  }
  return out;
}

// ---- the clock ----

function missionEnd() { return Math.max(D.end, 0.001); }

function setClock(t) {
  S.clock = Math.min(Math.max(0, num(t, 0)), missionEnd());
  S.dirty = true;
}

function nextEventTime(after) {
  for (const t of D.eventTimes) if (t > after + 1e-6) return t;
  return null;
}

function tick(prev) {
  return now => {
    const dt = Math.min(0.25, (now - prev) / 1000);
    if (S.playing) {
      setClock(S.clock + dt * S.speed);
      if (S.clock >= missionEnd() && (S.finished || !S.live)) S.playing = false;
    }
    if (S.live && !S.finished && S.follow) S.clock = missionEnd();
    if (S.dirty) render();
    requestAnimationFrame(tick(now));
  };
}

// ---- drawing ----

function render() {
  const started = performance.now();
  S.dirty = false;
  // Layout is read once, before anything is written: a read after a write forces the
  // browser to lay the page out again, and one per trigger arrow made a 20-drone page lag.
  S.trackW = trackWidth();
  if (S.structureDirty) { buildLanes(); S.structureDirty = false; S.itemsDirty = false; }
  else if (S.itemsDirty) { addLaneItems(); S.itemsDirty = false; }
  renderControls();
  renderLanes();
  renderMap();
  renderDroneList();
  renderGraphStates();
  renderSourceActive();
  document.body.dataset.clock = S.clock.toFixed(3);
  noteDrawn();
  S.renderTimes.push(performance.now() - started);
  if (S.renderTimes.length > LATENCIES_MAX) S.renderTimes.splice(0, S.renderTimes.length - LATENCIES_MAX);
}

// Live latency: from eamos emitting an event to the end of the render that drew it (the
// browser paints that frame right after). Only events emitted after the page had drawn its
// history count: what happened before it connected is old news, and until that first draw
// the page is loading (a thousand drones' mission text, graphs and history), not lagging.
function noteDrawn() {
  const now = wallNow();
  // The history is drawn when the frame with it has been laid out and painted, which the
  // browser does after this render: the next frame's start is that moment. (For a thousand
  // drones that layout took 145 ms in one run on a loaded host.)
  if (S.historyIn && S.liveFrom === Infinity && !S.historyFrame)
    if (document.hidden) S.liveFrom = now;  // no frames in a background tab
    else S.historyFrame = requestAnimationFrame(() => { S.liveFrom = wallNow(); });
  if (!S.undrawn.length) return;
  for (const emitted of S.undrawn) S.latencies.push(now - emitted);
  S.undrawn = [];
  if (S.latencies.length > LATENCIES_MAX) S.latencies.splice(0, S.latencies.length - LATENCIES_MAX);
}

function latencyStats(values) {
  const d = [...values].sort((a, b) => a - b);
  if (!d.length) return { count: 0, median: null, p95: null, max: null };
  const at = q => d[Math.min(d.length - 1, Math.ceil(q * d.length) - 1)];
  return { count: d.length, median: at(0.5), p95: at(0.95), max: d[d.length - 1] };
}

function renderControls() {
  const end = missionEnd();
  const scrub = $('scrub');
  scrub.max = String(end);
  if (document.activeElement !== scrub) scrub.value = String(S.clock);
  $('clock').textContent = S.clock.toFixed(2) + ' s / ' + end.toFixed(2) + ' s';
  $('clock').dataset.t = S.clock.toFixed(3);
  const mode = pageMode();
  putText($('mode'), { live: '● live', ended: 'live run ended', replay: 'replay', verify: 'verify run (replay)' }[mode]);
  $('mode').dataset.mode = mode;
  const [outcome, text] = outcomeShown();
  $('outcome').dataset.outcome = outcome;
  putText($('outcome'), text);
  $('follow').parentElement.hidden = mode !== 'live';
  $('play').disabled = S.playing;
  $('pause').disabled = !S.playing;
  $('next-failure').disabled = $('prev-failure').disabled = D.failures.length === 0;
  renderBanner();
}

function putText(node, text) { if (node.textContent !== text) node.textContent = text; }

// A live run is live until its outcome is in (the `mission` event), not until the server
// stops sending: a failed run's failsafes go on for a while after it ended.
function pageMode() {
  if (S.live) return S.finished || D.outcome ? 'ended' : 'live';
  return isVerify() ? 'verify' : 'replay';
}
function isVerify() { return !!S.mission && S.mission.run === 'verify'; }

// The header's outcome: the mission's, or for a verification what it found.
function outcomeShown() {
  if (isVerify()) {
    const n = D.violations.length;
    return n ? ['violations', n + (n === 1 ? ' violation' : ' violations')] : ['verified', 'no violations'];
  }
  return [D.outcome, D.outcome ? 'mission ' + D.outcome : ''];
}

// What went wrong, as one line under the header: the first failed action (drone, action,
// line, reason) and the mission's own reason; for a verification, its violations.
function bannerText() {
  const seconds = t => t.toFixed(2) + ' s';
  if (isVerify()) {
    const m = S.mission, n = D.violations.length, v = D.violations[0];
    const path = Number.isInteger(m.path) && Number.isInteger(m.paths) ? ` (path ${m.path} of ${m.paths} flown)` : '';
    if (!n) return { kind: 'verified', text: `Verification run${path}: no violations on this path` };
    return { kind: 'verify', failure: D.failures.find(f => f.kind === 'violation'),
             text: `Verification run${path}: ${n} ${n === 1 ? 'violation' : 'violations'} — first: ${v.kind} at ` +
                   `${seconds(v.t)}, ${v.drone}, line ${v.line}: ${v.text}` };
  }
  const f = D.failures.find(x => x.kind === 'action');
  if (f) {
    let text = `Mission failed at ${seconds(f.t)}: ${f.drone} · ${f.text} · line ${f.line} · ${f.reason || 'no reason given'}`;
    if (D.missionReason && !D.missionReason.includes(f.reason)) text += ' — ' + D.missionReason;
    return { kind: 'failed', failure: f, text };
  }
  if (D.outcome === 'failed')
    return { kind: 'failed', failure: D.failures.find(x => x.kind === 'mission'),
             text: `Mission failed at ${seconds(D.missionT || 0)}: ${D.missionReason || 'no reason given'}` };
  return null;
}

function renderBanner() {
  const b = bannerText(), banner = $('banner');
  banner.hidden = !b;
  if (!b) return;
  banner.dataset.kind = b.kind;
  putText($('banner-text'), b.text);
  const f = b.failure;
  banner.dataset.drone = f ? f.drone : '';
  banner.dataset.action = f && f.kind === 'action' ? f.name : '';
  banner.dataset.line = f ? String(f.line) : '';
  banner.dataset.reason = f ? f.reason : D.missionReason;
  banner.dataset.t = f ? String(f.t) : '';
  $('banner-show').hidden = !f;
  S.bannerFailure = f || null;
}

// ---- failures: next / previous, and what the selection says about one ----

// One stop per instant, the most telling failure there (a failed action before the
// failsafes and the mission's end it caused).
function failureStops() {
  const rank = { action: 0, violation: 1, error: 2, mission: 3, failsafe: 4 };
  const at = new Map();
  for (const f of D.failures) {
    const key = f.t.toFixed(6), best = at.get(key);
    if (!best || rank[f.kind] < rank[best.kind]) at.set(key, f);
  }
  return [...at.values()].sort((a, b) => a.t - b.t);
}

// Past the last failure "next" starts again from the first, before the first "previous"
// from the last: the buttons always go somewhere while there is a failure at all.
function jumpToFailure(direction) {
  const stops = failureStops();
  if (!stops.length) return;
  let i = -1;
  if (direction > 0) i = stops.findIndex(f => f.t > S.clock + 1e-6);
  else for (let k = stops.length - 1; k >= 0 && i < 0; k--) if (stops[k].t < S.clock - 1e-6) i = k;
  const wrapped = i < 0;
  if (wrapped) i = direction > 0 ? 0 : stops.length - 1;
  showFailure(stops[i], `failure ${i + 1} of ${stops.length}` +
                        (wrapped ? (direction > 0 ? ' (back to the first)' : ' (back to the last)') : ''));
}

function showFailure(f, prefix) {
  S.follow = false; $('follow').checked = false; S.playing = false;
  setClock(f.t);
  select({ nodes: f.nodes, line: f.line, drone: f.drone, text: (f.drone ? f.drone + ' · ' : '') + f.text, t: f.t,
           outcome: f.kind === 'action' ? 'failed' : f.kind, reason: f.reason, prefix });
}

function trackWidth() {
  const lanes = $('lanes');
  return Math.max(200, (lanes.clientWidth || 800) - 84);
}
function xOf(t) { return 76 + (t / axisEnd()) * S.trackW; }

// The time the lanes span. A finished trace spans its end; a live one rounds up with
// headroom, so what is drawn stays put as events come in and a frame rewrites only what
// changed (rescaling every bar on every event is what made a 20-drone page fall behind).
function axisEnd() {
  const end = missionEnd();
  if (!S.live || S.finished) return end;
  for (let scale = 1; ; scale *= 10)
    for (const step of [10, 15, 20, 30, 50, 75]) if (step * scale >= end * 1.1) return step * scale;
}

// Writes a style or an attribute only when it changes: an unchanged write still costs a restyle.
function put(node, property, value) {
  if (node['_s' + property] === value) return;
  node['_s' + property] = value;
  node.style[property] = value;
}
function putAttr(node, name, value) {
  if (node['_a' + name] === value) return;
  node['_a' + name] = value;
  node.setAttribute(name, value);
}
function flag(node, cls, on) {
  if (node['_' + cls] === on) return;
  node['_' + cls] = on;
  node.classList.toggle(cls, on);
}

// The lanes from scratch: on a new drone (or the first draw). Items come from addLaneItems.
function buildLanes() {
  const lanes = $('lanes');
  lanes.textContent = '';
  const useDom = D.drones.length <= DOM_LANES_MAX;
  lanes.hidden = !useDom;
  $('lanes-canvas').hidden = useDom;
  lanes.dataset.drones = String(D.drones.length);
  S.laneTiles = null;
  for (const item of [...D.bars, ...D.conds, ...D.violations, ...D.failMarks, ...D.giveWays]) item.el = null;
  for (const w of D.waitSpans ? D.waitSpans.values() : []) w.el = null;
  D.waitSpans = new Map();
  for (const tr of D.triggerList || []) tr.el = null;
  D.triggerList = [];
  $('triggers').textContent = '';
  D.condRows = new Map();
  if (!useDom) return;
  for (const d of D.drones) {
    const lane = el('div', 'lane');
    lane.dataset.drone = d.name;
    lane.style.setProperty('--drone', d.colour);
    lane.appendChild(el('div', 'lane-label', d.name));
    const track = el('div', 'track');
    lane.appendChild(track);
    lanes.appendChild(lane);
    d.track = track;
    d.lane = lane;
  }
  addLaneItems();
}

// Elements for the bars, marks and arrows that have none yet, and the bars that ended since.
function addLaneItems() {
  if (D.drones.length > DOM_LANES_MAX) return;
  const rows = barRows();
  D.bars.forEach((b, i) => {
    if (!b.el) { makeBar(b, i); b.changed = true; }
    if (b.changed) {
      b.el.dataset.end = b.end === null ? '' : String(b.end);
      b.el.dataset.outcome = b.outcome;
      b.el.title = b.text + (b.outcome ? ' — ' + b.outcome : '') + (b.reason ? ' (' + b.reason + ')' : '') +
                   '  line ' + b.line;
      b.changed = false;
    }
    // Actions that overlap in one drone (a motion and a picture) share the lane in rows.
    const [row, count] = rows.get(b);
    const h = Math.floor(28 / count);
    put(b.el, 'top', (2 + row * h) + 'px');
    put(b.el, 'height', (h - 1) + 'px');
    put(b.el, 'fontSize', count > 1 ? '9px' : '');
  });
  for (const c of D.conds) if (!c.el) makeCond(c);
  buildViolationMarks();
  buildFailMarks();
  buildGiveWayMarks();
  updateTriggers();
}

// An orange mark in the lane of the drone that gave way (⏸) and flew on (▶); a conflict it
// could not hold for is a ⚠. The other drone and their distance are its title.
function buildGiveWayMarks() {
  const glyph = { conflict: '⚠', give_way: '⏸', resume: '▶' };
  for (const w of D.giveWays) {
    const d = D.drones[D.droneIndex.get(w.drone)];
    if (w.el || !d || !d.track || (w.event === 'conflict' && !w.reason.includes('cannot be held'))) continue;
    const mark = el('div', 'give-way', glyph[w.event]);
    mark.dataset.drone = w.drone;
    mark.dataset.event = w.event;
    mark.dataset.other = w.other;
    mark.dataset.t = String(w.t);
    const apart = isFinite(w.distance) ? ` ${w.distance.toFixed(1)} m apart` : '';
    mark.title = `${w.drone} ${w.event.replace('_', ' ')} ${w.other} at ${w.t.toFixed(2)} s,${apart} (${w.reason})`;
    mark.addEventListener('click', () => select({ nodes: [], line: 0, drone: w.drone, text: mark.title, t: w.t,
                                                   outcome: w.event, reason: w.reason }));
    w.el = mark;
    d.track.appendChild(mark);
  }
}

function makeBar(b, i) {
  const bar = el('div', 'bar', b.name);
  bar.dataset.index = String(i);
  bar.dataset.drone = b.drone;
  bar.dataset.name = b.name;
  bar.dataset.line = String(b.line);
  bar.dataset.start = String(b.start);
  bar.dataset.node = b.nodes.join(' ');
  bar.addEventListener('click', () => select({ nodes: b.nodes, line: b.line, drone: b.drone, text: b.text || b.name,
                                                t: b.start, end: b.end === null ? undefined : b.end,
                                                outcome: b.end === null ? 'running' : b.outcome || 'succeeded',
                                                reason: b.reason }));
  b.el = bar;
  D.drones[D.droneIndex.get(b.drone)].track.appendChild(bar);
}

function makeCond(c) {
  const mark = el('div', 'cond', c.name + (c.value ? ' ✓' : ' ✗'));
  mark.dataset.drone = c.drone;
  mark.dataset.name = c.name;
  mark.dataset.line = String(c.line);
  mark.dataset.value = String(c.value);
  mark.dataset.t = String(c.t);
  mark.title = c.text + ' → ' + c.value + ' at ' + c.t.toFixed(2) + ' s';
  // Marks of one lane take turns between two rows, so neighbours do not overlap.
  const row = D.condRows.get(c.drone) || 0;
  D.condRows.set(c.drone, row + 1);
  mark.style.top = (row % 2 === 0 ? 42 : 54) + 'px';
  mark.addEventListener('click', () => select({ nodes: c.nodes, line: c.line, drone: c.drone, text: c.text, t: c.t,
                                                 outcome: c.value ? 'true' : 'false' }));
  c.el = mark;
  D.drones[D.droneIndex.get(c.drone)].track.appendChild(mark);
}

// A red mark per violation in its drone's lane; the diagnostic is its title.
function buildViolationMarks() {
  for (const v of D.violations) {
    const d = D.drones[D.droneIndex.get(v.drone)];
    if (v.el || !d || !d.track) continue;
    const mark = el('div', 'violation', '!');
    mark.dataset.drone = v.drone;
    mark.dataset.kind = v.kind;
    mark.dataset.line = String(v.line);
    mark.dataset.t = String(v.t);
    mark.title = v.kind + ' at ' + v.t.toFixed(2) + ' s (line ' + v.line + '): ' + v.text +
                 (v.others.length ? ' [with ' + v.others.join(', ') + ']' : '');
    mark.addEventListener('click', () => select({ nodes: [], line: v.line, drone: v.drone, text: v.drone + ' · ' + v.kind,
                                                   t: v.t, outcome: 'violation', reason: v.text }));
    v.el = mark;
    d.track.appendChild(mark);
  }
}

// A red ✗ where a drone's action failed, at the end of its red bar; the reason is its title.
function buildFailMarks() {
  for (const f of D.failMarks) {
    const d = D.drones[D.droneIndex.get(f.drone)];
    if (f.el || !d || !d.track) continue;
    const mark = el('div', 'fail-mark', '✗');
    mark.dataset.drone = f.drone;
    mark.dataset.name = f.name;
    mark.dataset.line = String(f.line);
    mark.dataset.t = String(f.t);
    mark.dataset.reason = f.reason;
    mark.title = `${f.text} failed at ${f.t.toFixed(2)} s (line ${f.line}): ${f.reason}`;
    mark.addEventListener('click', () => showFailure(f, 'failure'));
    f.el = mark;
    d.track.appendChild(mark);
  }
}

// Each bar's row in its lane (the first free one) and its lane's row count.
function barRows() {
  const free = new Map(), out = new Map();
  for (const b of D.bars) {
    if (!free.has(b.drone)) free.set(b.drone, []);
    const ends = free.get(b.drone);
    let row = ends.findIndex(e => e <= b.start + 1e-9);
    if (row < 0) { row = ends.length; ends.push(0); }
    ends[row] = b.end === null ? Infinity : b.end;
    out.set(b, row);
  }
  const result = new Map();
  for (const b of D.bars) result.set(b, [out.get(b), Math.min(3, free.get(b.drone).length)]);
  for (const [b, [row, count]] of result) if (row >= count) result.set(b, [count - 1, count]);
  return result;
}

// The arrows (and wait spans) as triggers() finds them now: the ones already drawn stay, new
// ones are added; only when an earlier one changed are they all drawn again.
function updateTriggers() {
  const svg = $('triggers');
  const NS = 'http://www.w3.org/2000/svg';
  const old = D.triggerList || [], now = triggers();
  const same = (a, b) => a.from === b.from && a.to === b.to && a.sent === b.sent && a.received === b.received &&
                         a.kind === b.kind && a.waitFrom === b.waitFrom;
  let kept = 0;
  while (kept < old.length && kept < now.length && old[kept].el && same(old[kept], now[kept])) kept++;
  if (kept < old.length) {
    for (const tr of old) if (tr.el) tr.el.remove();
    kept = 0;
  }
  if (!svg.querySelector('defs')) {
    const defs = document.createElementNS(NS, 'defs');
    defs.innerHTML = '<marker id="arrow" viewBox="0 0 10 10" refX="9" refY="5" markerWidth="7" markerHeight="7" orient="auto">' +
                     '<path d="M0,0 L10,5 L0,10 z" fill="#6a1b9a"/></marker>';
    svg.appendChild(defs);
  }
  D.triggerList = old.slice(0, kept).concat(now.slice(kept));
  for (const tr of D.triggerList.slice(kept)) drawTrigger(svg, tr);
  updateWaits();
}

// Whether `drone` was between actions just before `t` (a trigger that arrives while it
// still flies its previous action is no wait). Final once the clock of the trace passed t.
function idleBefore(drone, t) {
  for (const b of D.bars)
    if (b.drone === drone && b.start < t - 1e-9 && (b.end === null || b.end > t + 1e-9)) return false;
  return true;
}

// One hatched span per pause of a drone between two actions: from its last end to the last
// trigger it waited for. Several drones that each trigger it (the end of a PAR) make one
// span, labelled with the one it waited for last and how many others.
function updateWaits() {
  const groups = new Map();
  for (const tr of D.triggerList) {
    if (tr.received - tr.waitFrom <= 0.01) continue;
    if (tr.idle === undefined) tr.idle = idleBefore(tr.to, tr.received);
    if (!tr.idle) continue;
    const key = tr.to + '|' + tr.waitFrom;
    const g = groups.get(key);
    if (!g) groups.set(key, { to: tr.to, waitFrom: tr.waitFrom, last: tr, others: [] });
    else if (tr.received > g.last.received) { g.others.push(g.last.from); g.last = tr; }
    else g.others.push(tr.from);
  }
  for (const [key, w] of D.waitSpans) if (!groups.has(key)) { if (w.el) w.el.remove(); D.waitSpans.delete(key); }
  for (const [key, g] of groups) {
    let w = D.waitSpans.get(key);
    if (!w) { w = { el: null }; D.waitSpans.set(key, w); }
    Object.assign(w, { to: g.to, on: g.last.from, waitFrom: g.waitFrom, until: g.last.received,
                       others: [...new Set(g.others.filter(o => o !== g.last.from))] });
    const d = D.drones[D.droneIndex.get(w.to)];
    if (!w.el && d && d.track) { w.el = el('div', 'wait'); d.track.appendChild(w.el); }
    if (!w.el) continue;
    w.el.dataset.drone = w.to;
    w.el.dataset.on = w.on;
    w.el.dataset.wait = (w.until - w.waitFrom).toFixed(2);
    w.el.dataset.others = w.others.join(' ');
    w.el.title = `${w.to} waited ${(w.until - w.waitFrom).toFixed(2)} s, from ${w.waitFrom.toFixed(2)} s until ` +
                 `${w.on}'s trigger at ${w.until.toFixed(2)} s` +
                 (w.others.length ? ` (also triggered by ${w.others.join(', ')}, earlier)` : '');
  }
}

// The spans' places, and their labels as long as fits: "waits 2.55 s on D1 (+2)", "2.55 s · D1", or none.
function renderWaits(px, now) {
  for (const w of D.waitSpans.values()) {
    if (!w.el) continue;
    const width = Math.max(2, px(w.until - w.waitFrom));
    put(w.el, 'left', px(w.waitFrom) + 'px');
    put(w.el, 'width', width + 'px');
    flag(w.el, 'future', w.waitFrom > now + 1e-9);
    const secs = (w.until - w.waitFrom).toFixed(2) + ' s';
    const full = `waits ${secs} on ${w.on}` + (w.others.length ? ` (+${w.others.length})` : '');
    const short = `${secs} · ${w.on}`;
    putText(w.el, width >= full.length * 5.6 + 4 ? full : width >= short.length * 5.6 + 4 ? short : '');
  }
}

function drawTrigger(svg, tr) {
  const NS = 'http://www.w3.org/2000/svg';
  const line = document.createElementNS(NS, 'path');
  line.setAttribute('class', 'trigger' + (tr.kind === 'abort' ? ' abort' : ''));
  line.setAttribute('marker-end', 'url(#arrow)');
  line.dataset.from = tr.from;
  line.dataset.to = tr.to;
  line.dataset.node = String(tr.node ?? '');
  line.dataset.sent = String(tr.sent);
  line.dataset.received = String(tr.received);
  line.dataset.wait = (tr.received - tr.waitFrom).toFixed(2);
  const title = document.createElementNS(NS, 'title');
  title.textContent = tr.to + ' waited ' + (tr.received - tr.waitFrom).toFixed(2) + ' s on ' + tr.from;
  line.appendChild(title);
  svg.appendChild(line);
  tr.el = line;
}

function barState(b) {
  if (b.start > S.clock + 1e-9) return 'future';
  if (b.end === null || b.end > S.clock + 1e-9) return 'running';
  return b.outcome || 'succeeded';
}

function renderLanes() {
  if (D.drones.length > DOM_LANES_MAX) { renderLanesCanvas(); return; }
  const w = S.trackW, end = axisEnd(), px = t => (t / end) * w;
  const now = S.clock;
  for (const b of D.bars) {
    if (!b.el) continue;
    const state = barState(b);
    const stop = b.end === null ? D.end : b.end;
    const shown = state === 'running' ? Math.min(now, stop) : stop;
    putAttr(b.el, 'data-state', state);
    put(b.el, 'left', px(b.start) + 'px');
    put(b.el, 'width', Math.max(3, px((state === 'future' ? stop : shown) - b.start)) + 'px');
  }
  for (const c of D.conds) {
    if (!c.el) continue;
    put(c.el, 'left', px(c.t) + 'px');
    flag(c.el, 'future', c.t > now + 1e-9);
  }
  for (const v of D.violations) {
    if (!v.el) continue;
    put(v.el, 'left', px(v.t) + 'px');
    flag(v.el, 'future', v.t > now + 1e-9);
  }
  for (const w of D.giveWays) {
    if (!w.el) continue;
    put(w.el, 'left', px(w.t) + 'px');
    flag(w.el, 'future', w.t > now + 1e-9);
  }
  const failedNow = new Set();
  for (const f of D.failMarks) {
    if (f.t <= now + 1e-9) failedNow.add(f.drone);
    if (!f.el) continue;
    put(f.el, 'left', px(f.t) + 'px');
    flag(f.el, 'future', f.t > now + 1e-9);
  }
  for (const d of D.drones) if (d.lane) flag(d.lane, 'failed', failedNow.has(d.name));
  renderWaits(px, now);
  // The lanes' size from what is known, not read back from the page (see render).
  const laneH = 68, height = D.drones.length * laneH;
  const svg = $('triggers');
  putAttr(svg, 'width', String(w + 84));
  putAttr(svg, 'height', String(height));
  for (const tr of D.triggerList || []) {
    const a = D.droneIndex.get(tr.from), b = D.droneIndex.get(tr.to);
    const y1 = a * laneH + 14, y2 = b * laneH + (b > a ? 4 : 26);
    const x1 = xOf(tr.sent), x2 = xOf(tr.received);
    putAttr(tr.el, 'd', `M${x1},${y1} C${x1 + 30},${y1} ${x2 - 30},${y2} ${x2},${y2}`);
    flag(tr.el, 'future', tr.received > now + 1e-9);
  }
  const head = $('playhead');
  put(head, 'left', xOf(now) + 'px');
  put(head, 'height', height + 'px');
}

// Level of detail for large fleets: one pixel row per drone (up to 8), bars merged below a
// pixel. The picture is kept from frame to frame in columns of LANE_TILE px, each a canvas of
// its own, and a frame draws only what changed since the last one: the bars that started or
// ended and the running bars' growth up to the clock. The browser copies a changed canvas
// when it commits a frame: with one canvas of a thousand rows changing in every frame, the
// commit took 4.2 ms a frame (1.7 ms without the lanes); here a frame changes 2-3 columns.
// The playhead is an element over the columns, so moving it changes no canvas.
const LANE_TILE = 128;
function renderLanesCanvas() {
  const box = $('lanes-canvas'), head = $('playhead');
  // At most 1,200 px tall: a thousand rows of 4 px (6 million pixels) made a live page fall
  // seconds behind.
  const rowH = Math.max(1, Math.min(8, Math.floor(1200 / D.drones.length)));
  const w = Math.max(400, $('lanes-scroll').clientWidth - 4), h = rowH * D.drones.length;
  const end = axisEnd(), now = S.clock;
  // Everything again when the picture's geometry changes (a new axis: a live run's has
  // headroom, so that is rare), a new mission, or the clock goes back.
  const key = [w, h, end, rowH].join(' ');
  let L = S.laneTiles;
  if (!L || L.key !== key || L.bars !== D.bars || now < L.clock - 1e-9) L = S.laneTiles = laneTiles(box, key, w, h, end, rowH);
  const toX = t => (t / end) * w;
  L.frame++;
  // Bars drawn as running that have ended by now: their outcome over their whole span.
  for (const b of L.running) {
    if (b.end === null || b.end > now + 1e-9) continue;
    laneSpan(L, b, toX(b.start), toX(b.end), b.outcome || 'succeeded');
    L.running.delete(b);
  }
  // Bars that started by now and are not drawn yet (in a live run, the ones that came in).
  for (; L.next < D.bars.length; L.next++) L.pending.push(D.bars[L.next]);
  if (L.pending.length) L.pending = L.pending.filter(b => {
    if (b.start > now + 1e-9) return true;
    L.drawn++;
    const ended = b.end !== null && b.end <= now + 1e-9;
    laneSpan(L, b, toX(b.start), toX(ended ? b.end : now), ended ? (b.outcome || 'succeeded') : 'running');
    if (!ended) L.running.add(b);
    return false;
  });
  // The running bars grow to the clock: only the columns it crossed since.
  const x = toX(now);
  if (x >= L.x + 0.5) {
    for (const b of L.running) laneSpan(L, b, Math.max(toX(b.start), L.x - 1), x, 'running');
    L.x = x;
  }
  L.clock = now;
  S.laneColumns.renders++;
  S.laneColumns.columns = L.tiles.length;
  put(head, 'left', x + 'px');
  put(head, 'height', h + 'px');
  box.dataset.drones = String(D.drones.length);
  box.dataset.bars = String(L.drawn);
}

// The columns for a picture of width w and height h, cleared (built again when the width changes).
function laneTiles(box, key, w, h, end, rowH) {
  const count = Math.ceil(w / LANE_TILE);
  const canvases = [...box.children];
  while (canvases.length > count) box.removeChild(canvases.pop());
  while (canvases.length < count) canvases.push(box.appendChild(document.createElement('canvas')));
  const tiles = canvases.map((c, i) => {
    const tw = Math.min(LANE_TILE, w - i * LANE_TILE);
    if (c.width !== tw) c.width = tw;
    if (c.height !== h) c.height = h; else c.getContext('2d').clearRect(0, 0, tw, h);
    return { g: c.getContext('2d'), x0: i * LANE_TILE, w: tw };
  });
  return { key, tiles, rowH, bars: D.bars, next: 0, pending: [], running: new Set(), drawn: 0, clock: 0, x: 0, frame: 0 };
}

const BAR_COLOURS = { succeeded: '#2e7d32', failed: '#c62828', preempted: '#ef6c00', cancelled: '#757575', running: '#1565c0' };
// Bar b's row from x0 to x1 (at least a pixel wide) in the colour of `state`, in each column it crosses.
function laneSpan(L, b, x0, x1, state) {
  x1 = Math.max(x1, x0 + 1);
  const row = D.droneIndex.get(b.drone), y = row * L.rowH, rh = L.rowH - (L.rowH > 3 ? 1 : 0);
  const first = Math.max(0, Math.floor(x0 / LANE_TILE)), last = Math.min(L.tiles.length - 1, Math.floor(x1 / LANE_TILE));
  for (let i = first; i <= last; i++) {
    const t = L.tiles[i];
    if (t.frame !== L.frame) { t.frame = L.frame; S.laneColumns.drawn++; }
    t.g.fillStyle = BAR_COLOURS[state] || '#2e7d32';
    t.g.fillRect(x0 - t.x0, y, x1 - x0, rh);
  }
}

// ---- map ----

function positionAt(drone, t) {
  const samples = D.telemetry.get(drone.name);
  if (!samples || !samples.length) return drone.home ? { x: drone.home[0], y: drone.home[1], z: drone.home[2], home: true } : null;
  let lo = 0, hi = samples.length - 1;
  if (t <= samples[0].t) return samples[0];
  if (t >= samples[hi].t) return samples[hi];
  while (hi - lo > 1) { const mid = (lo + hi) >> 1; if (samples[mid].t <= t) lo = mid; else hi = mid; }
  const a = samples[lo], b = samples[hi], f = (t - a.t) / Math.max(1e-9, b.t - a.t);
  return { x: a.x + (b.x - a.x) * f, y: a.y + (b.y - a.y) * f, z: a.z + (b.z - a.z) * f, battery: a.battery, mode: a.mode };
}

function worldBounds() {
  let minX = Infinity, maxX = -Infinity, minY = Infinity, maxY = -Infinity, maxZ = 1;
  const take = (x, y, z) => {
    minX = Math.min(minX, x); maxX = Math.max(maxX, x); minY = Math.min(minY, y); maxY = Math.max(maxY, y);
    maxZ = Math.max(maxZ, z || 0);
  };
  for (const d of D.drones) {
    if (d.home) take(d.home[0], d.home[1], d.home[2]);
    if (d.geofence && Array.isArray(d.geofence.polygon)) for (const p of d.geofence.polygon) take(num(p[0], 0), num(p[1], 0), 0);
  }
  if (D.telemetry.size) { take(D.seen.minX, D.seen.minY, D.seen.maxZ); take(D.seen.maxX, D.seen.maxY, 0); }
  for (const v of D.violations) if (isFinite(v.x) && isFinite(v.y)) take(v.x, v.y, 0);
  if (!isFinite(minX)) { minX = -10; maxX = 10; minY = -10; maxY = 10; }
  const pad = Math.max(2, 0.08 * Math.max(maxX - minX, maxY - minY));
  return { minX: minX - pad, maxX: maxX + pad, minY: minY - pad, maxY: maxY + pad, maxZ: maxZ * 1.15 };
}

function renderMap() {
  const canvas = $('map'), g = canvas.getContext('2d');
  const W = canvas.width, H = canvas.height, B = mapBounds();
  const scale = Math.min(W / (B.maxX - B.minX), H / (B.maxY - B.minY));
  const X = x => (x - B.minX) * scale + (W - (B.maxX - B.minX) * scale) / 2;
  const Y = y => H - ((y - B.minY) * scale + (H - (B.maxY - B.minY) * scale) / 2);
  g.clearRect(0, 0, W, H);
  drawGrid(g, W, H, B, X, Y);
  const many = D.drones.length > 100;
  const seenFences = new Set();
  for (const d of D.drones) {
    const f = d.geofence;
    if (d.fenceKey && !seenFences.has(d.fenceKey)) {
      seenFences.add(d.fenceKey);
      g.strokeStyle = '#c62828'; g.setLineDash([6, 4]); g.beginPath();
      f.polygon.forEach((p, i) => (i ? g.lineTo : g.moveTo).call(g, X(num(p[0], 0)), Y(num(p[1], 0))));
      g.closePath(); g.stroke(); g.setLineDash([]);
    }
  }
  if (many) g.drawImage(trailLayer(W, H, B, X, Y), 0, 0);
  const failedNow = failedDronesAt(S.clock);
  // Each drone's position at the clock, found once for the map and the side view.
  const at = D.drones.map(d => positionAt(d, S.clock));
  for (const d of D.drones) {
    const samples = D.telemetry.get(d.name) || [];
    const p = at[d.index];
    // A large fleet's tracks are on the layer, up to each drone's last sample.
    if (samples.length > 1 && !many) {
      g.strokeStyle = d.colour; g.globalAlpha = 0.6; g.lineWidth = 1.5; g.beginPath();
      let first = true;
      for (let i = 0; i < samples.length && samples[i].t <= S.clock; i++) {
        (first ? g.moveTo : g.lineTo).call(g, X(samples[i].x), Y(samples[i].y)); first = false;
      }
      if (p && !first) g.lineTo(X(p.x), Y(p.y));
      g.stroke(); g.globalAlpha = 1;
    }
    if (d.home && !many) { g.strokeStyle = d.colour; g.strokeRect(X(d.home[0]) - 4, Y(d.home[1]) - 4, 8, 8); }
    if (!p) continue;
    g.fillStyle = d.colour;
    // A square of 4 px for each of a thousand drones: the browser rasterises a canvas's
    // shapes when it hands the frame on, and a thousand round dots cost as much as the rest.
    if (many) g.fillRect(X(p.x) - 2, Y(p.y) - 2, 4, 4);
    else { g.beginPath(); g.arc(X(p.x), Y(p.y), 5, 0, 2 * Math.PI); g.fill(); }
    const failed = failedNow.get(d.name);
    if (failed) { g.strokeStyle = '#d50000'; g.lineWidth = 2; g.beginPath(); g.arc(X(p.x), Y(p.y), 9, 0, 2 * Math.PI);
                  g.stroke(); g.lineWidth = 1; }
    if (!many) {
      g.fillStyle = failed ? '#d50000' : '#222'; g.font = (failed ? 'bold ' : '') + '11px sans-serif';
      g.fillText(d.name + (failed ? ' ✗ failed' : ''), X(p.x) + 11, Y(p.y) - 8);
    }
  }
  drawViolations(g, X, Y, many);
  drawGiveWays(g, X, Y, many);
  drawFailures(g, X, Y);
  renderSide(B, at);
  const hasTelemetry = D.telemetry.size > 0;
  putText($('map-note'), hasTelemetry ? '' : (D.drones.some(d => d.home) ?
    'this trace has no telemetry: homes only' : 'this trace has no telemetry and names no homes'));
}

// Large fleets: every track so far sits on a layer of its own that each frame extends with
// the samples that came in since (a few per frame), instead of drawing a thousand tracks
// again; a track ends at the drone's last sample, the dot goes on between samples. Drawn
// again from the start, thinned to 50 points a track, when the map's scale changes or the
// clock goes back.
function trailLayer(W, H, B, X, Y) {
  const key = [W, H, B.minX, B.maxX, B.minY, B.maxY].join(' ');
  let L = S.trails;
  if (!L || L.key !== key || S.clock < L.clock) {
    const canvas = L ? L.canvas : document.createElement('canvas');
    canvas.width = W; canvas.height = H;  // also clears it
    L = S.trails = { key, canvas, clock: 0, upTo: new Map() };
  }
  const g = L.canvas.getContext('2d');
  g.globalAlpha = 0.6; g.lineWidth = 1.5;
  for (const d of D.drones) {
    const samples = D.telemetry.get(d.name);
    const from = L.upTo.get(d.name) || 0;
    let to = from;
    while (samples && to < samples.length && samples[to].t <= S.clock) to++;
    if (to > from) {
      const step = Math.max(1, Math.floor((to - from) / 50));
      const start = from > 0 ? from - 1 : 0;
      g.strokeStyle = d.colour; g.beginPath();
      g.moveTo(X(samples[start].x), Y(samples[start].y));
      for (let i = start + step; i < to; i += step) g.lineTo(X(samples[i].x), Y(samples[i].y));
      g.lineTo(X(samples[to - 1].x), Y(samples[to - 1].y));
      g.stroke();
      L.upTo.set(d.name, to);
    }
  }
  L.clock = S.clock;
  return L.canvas;
}

// The map of a large fleet keeps its scale while the drones fly inside it and grows with a
// margin when one leaves it, so the tracks' layer is rarely drawn again; a small fleet's map
// fits it exactly.
function mapBounds() {
  const B = worldBounds();
  if (D.drones.length <= 100) return B;
  const K = S.mapBounds;
  if (K && B.minX >= K.minX && B.maxX <= K.maxX && B.minY >= K.minY && B.maxY <= K.maxY && B.maxZ <= K.maxZ) return K;
  const m = 0.1 * Math.max(B.maxX - B.minX, B.maxY - B.minY);
  const U = K || B;
  S.mapBounds = { minX: Math.min(U.minX, B.minX - m), maxX: Math.max(U.maxX, B.maxX + m), minY: Math.min(U.minY, B.minY - m),
                  maxY: Math.max(U.maxY, B.maxY + m), maxZ: Math.max(U.maxZ, B.maxZ * 1.2) };
  return S.mapBounds;
}

// Each drone's failed action once the clock has passed it (the first, as failedBy).
function failedDronesAt(t) {
  const out = new Map();
  for (const f of D.failMarks) if (f.t <= t + 1e-9 && !out.has(f.drone)) out.set(f.drone, f);
  return out;
}

// The failed action of `drone`, once the clock has passed it; null otherwise.
function failedBy(drone, t) {
  for (const f of D.failMarks) if (f.drone === drone && f.t <= t + 1e-9) return f;
  return null;
}

// A red cross where each failed action's drone was when it failed.
function drawFailures(g, X, Y) {
  g.strokeStyle = '#d50000'; g.lineWidth = 2.5;
  for (const f of D.failMarks) {
    const d = D.drones[D.droneIndex.get(f.drone)];
    const p = d && f.t <= S.clock + 1e-9 ? positionAt(d, f.t) : null;
    if (!p) continue;
    const x = X(p.x), y = Y(p.y);
    g.beginPath(); g.moveTo(x - 6, y - 6); g.lineTo(x + 6, y + 6); g.moveTo(x + 6, y - 6); g.lineTo(x - 6, y + 6); g.stroke();
  }
  g.lineWidth = 1;
}

// Each drone holding for another now: an orange ring on it and a dashed line to the drone it
// gives way to, until it flies on.
function drawGiveWays(g, X, Y, many) {
  const holding = new Map();
  for (const w of D.giveWays) {
    if (w.t > S.clock + 1e-9) continue;
    if (w.event === 'give_way') holding.set(w.drone, w);
    if (w.event === 'resume') holding.delete(w.drone);
  }
  g.strokeStyle = '#ff8c00'; g.lineWidth = 2;
  for (const w of holding.values()) {
    const a = D.drones[D.droneIndex.get(w.drone)], b = D.drones[D.droneIndex.get(w.other)];
    const p = a && positionAt(a, S.clock), q = b && positionAt(b, S.clock);
    if (!p) continue;
    g.beginPath(); g.arc(X(p.x), Y(p.y), 11, 0, 2 * Math.PI); g.stroke();
    if (q) { g.setLineDash([4, 3]); g.beginPath(); g.moveTo(X(p.x), Y(p.y)); g.lineTo(X(q.x), Y(q.y)); g.stroke();
             g.setLineDash([]); }
    if (!many) { g.fillStyle = '#ff8c00'; g.font = '11px sans-serif';
                 g.fillText('gives way to ' + w.other, X(p.x) + 13, Y(p.y) + 16); }
  }
  g.lineWidth = 1;
}

// Violations that have happened by now: a red ring where the drone was.
function drawViolations(g, X, Y, many) {
  g.strokeStyle = '#d50000'; g.lineWidth = 2;
  for (const v of D.violations) {
    if (v.t > S.clock + 1e-9 || !isFinite(v.x) || !isFinite(v.y)) continue;
    g.beginPath(); g.arc(X(v.x), Y(v.y), 9, 0, 2 * Math.PI); g.stroke();
    if (!many) { g.fillStyle = '#d50000'; g.font = '11px sans-serif'; g.fillText(v.kind, X(v.x) + 11, Y(v.y) + 14); }
  }
  g.lineWidth = 1;
}

function drawGrid(g, W, H, B, X, Y) {
  const span = Math.max(B.maxX - B.minX, B.maxY - B.minY);
  const step = Math.pow(10, Math.floor(Math.log10(span / 2)));
  g.strokeStyle = '#eee'; g.fillStyle = '#aaa'; g.font = '10px sans-serif'; g.lineWidth = 1;
  for (let x = Math.ceil(B.minX / step) * step; x <= B.maxX; x += step) {
    g.beginPath(); g.moveTo(X(x), 0); g.lineTo(X(x), H); g.stroke(); g.fillText(String(+x.toFixed(2)), X(x) + 2, H - 2);
  }
  for (let y = Math.ceil(B.minY / step) * step; y <= B.maxY; y += step) {
    g.beginPath(); g.moveTo(0, Y(y)); g.lineTo(W, Y(y)); g.stroke(); g.fillText(String(+y.toFixed(2)), 2, Y(y) - 2);
  }
}

function renderSide(B, at) {
  const canvas = $('side'), g = canvas.getContext('2d');
  const W = canvas.width, H = canvas.height;
  const X = x => ((x - B.minX) / (B.maxX - B.minX)) * W;
  const Z = z => H - 10 - (z / B.maxZ) * (H - 20);
  g.clearRect(0, 0, W, H);
  g.strokeStyle = '#8d6e63'; g.beginPath(); g.moveTo(0, Z(0)); g.lineTo(W, Z(0)); g.stroke();
  const fence = D.drones.map(d => d.geofence).find(f => f && typeof f.max_altitude === 'number');
  if (fence) { g.strokeStyle = '#c62828'; g.setLineDash([6, 4]); g.beginPath(); g.moveTo(0, Z(fence.max_altitude));
    g.lineTo(W, Z(fence.max_altitude)); g.stroke(); g.setLineDash([]); }
  for (const d of D.drones) {
    const p = at[d.index];
    if (!p) continue;
    g.fillStyle = d.colour;
    if (D.drones.length > 100) g.fillRect(X(p.x) - 2, Z(p.z) - 2, 4, 4);  // as on the map
    else { g.beginPath(); g.arc(X(p.x), Z(p.z), 4, 0, 2 * Math.PI); g.fill(); }
  }
  g.fillStyle = '#888'; g.font = '10px sans-serif'; g.fillText(B.maxZ.toFixed(1) + ' m', 2, 10);
}

function currentAction(name) {
  let last = null;
  for (const b of D.bars) if (b.drone === name && b.start <= S.clock + 1e-9 && (b.end === null || b.end > S.clock + 1e-9)) last = b;
  return last;
}

function renderDroneList() {
  const list = $('drone-list');
  if (D.drones.length > DOM_LANES_MAX) {
    // Written when the fleet grows, not every frame: a rewritten list is laid out again.
    const summary = D.drones.length + ' drones (too many to list; hover the lanes)';
    if (list.children.length !== 1 || list.firstChild.textContent !== summary) {
      list.textContent = '';
      list.appendChild(el('li', '', summary));
    }
    return;
  }
  if (list.children.length !== D.drones.length) {
    list.textContent = '';
    for (const d of D.drones) {
      const li = el('li');
      li.dataset.drone = d.name;
      const sw = el('span', 'swatch'); sw.style.background = d.colour;
      li.appendChild(sw);
      li.appendChild(el('span', 'text'));
      list.appendChild(li);
    }
  }
  D.drones.forEach((d, i) => {
    const li = list.children[i];
    const p = positionAt(d, S.clock), act = currentAction(d.name);
    li.dataset.action = act ? act.name : '';
    const failed = failedBy(d.name, S.clock);
    flag(li, 'failed', !!failed);
    li.dataset.failed = failed ? failed.name : '';
    let text = d.name + '  ' + (failed ? '✗ ' + failed.text + ' failed: ' + failed.reason + '  ' : '') +
               (act ? act.text || act.name : failed ? '' : '—');
    if (p) {
      li.dataset.x = p.x.toFixed(2); li.dataset.y = p.y.toFixed(2); li.dataset.z = p.z.toFixed(2);
      text += `  (${p.x.toFixed(1)}, ${p.y.toFixed(1)}, ${p.z.toFixed(1)})`;
      if (typeof p.battery === 'number') text += `  ${p.battery.toFixed(0)} %`;
    }
    li.lastChild.textContent = text;
  });
}

// ---- graphs ----

function sanitiseSvg(text) {
  const doc = new DOMParser().parseFromString(text, 'image/svg+xml');
  const svg = doc.documentElement;
  if (!svg || svg.nodeName !== 'svg') return null;
  for (const bad of svg.querySelectorAll('script, foreignObject, iframe, a')) {
    if (bad.nodeName === 'a') bad.replaceWith(...bad.childNodes); else bad.remove();
  }
  for (const e of svg.querySelectorAll('*')) {
    for (const attr of [...e.attributes]) {
      if (/^on/i.test(attr.name) || /href$/i.test(attr.name)) e.removeAttribute(attr.name);
    }
  }
  return document.importNode(svg, true);
}

function buildGraphSelect() {
  const select = $('graph-select');
  select.textContent = '';
  const graphs = S.mission && Array.isArray(S.mission.graphs) ? S.mission.graphs : [];
  graphs.forEach((g, i) => { const o = el('option', '', str(g.name)); o.value = String(i); select.appendChild(o); });
  select.hidden = graphs.length === 0;
  $('graph-note').textContent = S.mission ? str(S.mission.graph_note) : '';
  showGraph(Math.min(S.graphIndex, Math.max(0, graphs.length - 1)));
}

function showGraph(index) {
  S.graphIndex = index;
  const box = $('graph');
  box.textContent = '';
  const graphs = S.mission && Array.isArray(S.mission.graphs) ? S.mission.graphs : [];
  const g = graphs[index];
  if (!g) return;
  $('graph-select').value = String(index);
  const svg = sanitiseSvg(str(g.svg));
  if (!svg) return;
  svg.id = 'graph-svg';
  // Graphviz sizes the picture in points; the viewBox keeps its layout at the panel's width.
  svg.removeAttribute('width');
  svg.removeAttribute('height');
  box.dataset.graph = str(g.name);
  for (const node of svg.querySelectorAll('g.node')) {
    const title = node.querySelector('title');
    const name = title ? title.textContent : '';
    let id = null, holder = '';
    if (/^n\d+$/.test(name)) id = Number(name.slice(1));
    else if (/^m\d+$/.test(name) && Array.isArray(g.mdg_nodes)) {
      const m = g.mdg_nodes[Number(name.slice(1))];
      if (Array.isArray(m)) { id = m[0]; holder = str(m[1]); }
    }
    if (id === null) continue;
    node.dataset.node = String(id);
    if (holder) node.dataset.holder = holder;
    node.addEventListener('click', () => {
      if (G.dragged) return;  // the end of a pan, not a click on the node
      const n = D.nodes.get(id);
      select({ nodes: [id], line: n ? n.line : 0, drone: n ? n.drone : '', text: n ? n.label : '' });
    });
  }
  box.appendChild(svg);
  initGraphView(svg);
  S.dirty = true;
}

// ---- the graph's zoom and pan: the SVG's viewBox, kept at the panel's aspect ----

const G = { svg: null, base: null, view: null, drag: null, dragged: false };

function graphBox() {
  const box = $('graph');
  return { w: box.clientWidth || 600, h: box.clientHeight || 560 };
}

// Graphviz gives the picture's viewBox (in points). The first view fits its width, from the
// top (a MEG is read from its start), or the whole picture when that is shorter than the
// panel; but never smaller than GRAPH_READABLE pixels a point, where its labels can be read:
// a wide graph opens on its top middle, and "fit" shows it whole.
const GRAPH_READABLE = 0.75;
function initGraphView(svg) {
  const vb = svg.viewBox && svg.viewBox.baseVal;
  G.svg = svg;
  G.base = vb && vb.width > 0 ? { x: vb.x, y: vb.y, w: vb.width, h: vb.height } : null;
  svg.setAttribute('preserveAspectRatio', 'xMidYMid meet');
  if (!G.base) return;
  const { w, h } = graphBox(), b = G.base;
  const viewW = Math.min(b.w, w / GRAPH_READABLE);
  if (viewW === b.w && b.w * h / w >= b.h) fitGraph();
  else setGraphView({ x: b.x + (b.w - viewW) / 2, y: b.y, w: viewW });
}

function setGraphView(v) {
  const { w, h } = graphBox();
  v.h = v.w * h / w;  // the panel's aspect: a pixel is as wide as it is high, and pans map 1:1
  G.view = v;
  G.svg.setAttribute('viewBox', `${v.x} ${v.y} ${v.w} ${v.h}`);
  $('graph').dataset.zoom = (G.base.w / v.w).toFixed(3);
}

function fitGraph() {
  if (!G.base) return;
  const { w, h } = graphBox(), b = G.base;
  const vw = Math.max(b.w, b.h * w / h), vh = vw * h / w;
  setGraphView({ x: b.x - (vw - b.w) / 2, y: b.y - (vh - b.h) / 2, w: vw });
}

// Zooms by `factor` (>1: closer) keeping the point at (fx, fy), fractions of the panel, still.
function zoomGraph(factor, fx = 0.5, fy = 0.5) {
  if (!G.view) return;
  const v = G.view, span = Math.max(G.base.w, G.base.h);
  const w = Math.min(span * 4, Math.max(span / 40, v.w / factor));
  setGraphView({ x: v.x + fx * v.w - fx * w, y: v.y + fy * v.h - fy * (w * v.h / v.w), w });
}

// Pans the selected node to the middle of the panel when it is not in view.
function bringIntoView(node) {
  if (!G.view) return;
  const box = $('graph').getBoundingClientRect(), r = node.getBoundingClientRect();
  if (r.left >= box.left && r.right <= box.right && r.top >= box.top && r.bottom <= box.bottom) return;
  const scale = G.view.w / box.width;
  const dx = (r.left + r.width / 2 - (box.left + box.width / 2)) * scale;
  const dy = (r.top + r.height / 2 - (box.top + box.height / 2)) * scale;
  setGraphView({ x: G.view.x + dx, y: G.view.y + dy, w: G.view.w });
}

function wireGraphView() {
  const box = $('graph');
  $('zoom-in').onclick = () => zoomGraph(1.5);
  $('zoom-out').onclick = () => zoomGraph(1 / 1.5);
  $('zoom-fit').onclick = () => fitGraph();
  box.addEventListener('wheel', e => {
    if (!G.view) return;
    e.preventDefault();
    const r = box.getBoundingClientRect();
    zoomGraph(Math.pow(1.0015, -e.deltaY), (e.clientX - r.left) / r.width, (e.clientY - r.top) / r.height);
  }, { passive: false });
  box.addEventListener('pointerdown', e => {
    if (!G.view || e.button !== 0) return;
    G.drag = { x: e.clientX, y: e.clientY, view: { ...G.view }, id: e.pointerId };
    G.dragged = false;
  });
  box.addEventListener('pointermove', e => {
    const d = G.drag;
    if (!d || e.pointerId !== d.id) return;
    const dx = e.clientX - d.x, dy = e.clientY - d.y;
    if (!G.dragged && Math.hypot(dx, dy) < 4) return;
    if (!G.dragged) { G.dragged = true; box.setPointerCapture(e.pointerId); box.classList.add('panning'); }
    const scale = d.view.w / box.getBoundingClientRect().width;
    setGraphView({ x: d.view.x - dx * scale, y: d.view.y - dy * scale, w: d.view.w });
  });
  const end = () => { G.drag = null; box.classList.remove('panning'); setTimeout(() => { G.dragged = false; }, 0); };
  box.addEventListener('pointerup', end);
  box.addEventListener('pointercancel', end);
}

function stateAt(id) {
  const h = D.nodeHistory.get(id);
  let state = null;
  if (h) for (const s of h) { if (s.t <= S.clock + 1e-9) state = s.state; else break; }
  if (state) return state;
  return D.outcome && S.clock >= D.end - 1e-9 ? 'not-run' : 'waiting';
}

function renderGraphStates() {
  for (const node of $('graph').querySelectorAll('g.node[data-node]')) {
    const state = stateAt(Number(node.dataset.node));
    if (node.dataset.state === state) continue;
    node.dataset.state = state;
    for (const shape of node.querySelectorAll('ellipse, polygon, path')) shape.setAttribute('fill', STATE_FILL[state] || '#fff');
  }
}

// ---- mission text and selection ----

// The mission text in blocks of SOURCE_BLOCK lines that the browser lays out and paints only
// when in view (content-visibility). A block is one text node until it comes near the view,
// when it gets an element per line (numbered, for the highlights): a generated mission of
// 27,000 lines as elements is 108,000 objects to build, style and lay out, and laying them
// out every frame is what made a thousand-drone live page lag seconds. Every line stays in
// the page as text, so the browser's find still finds it.
const SOURCE_BLOCK = 200;
function buildSource() {
  const pre = $('source');
  pre.textContent = '';
  if (S.sourceObserver) S.sourceObserver.disconnect();
  S.activeLines = new Set();
  S.sourceBlocks = [];
  S.selectedLine = 0;
  const text = S.mission ? str(S.mission.source) : '';
  if (!text) { pre.textContent = 'the mission text is not in this trace'; return; }
  const lines = text.split('\n');
  S.sourceObserver = new IntersectionObserver(entries => {
    for (const e of entries) if (e.isIntersecting) fillBlock(e.target.block);
  }, { root: pre, rootMargin: '400px 0px' });
  for (let first = 0; first < lines.length; first += SOURCE_BLOCK) {
    const div = el('div', 'src-block');
    const block = { el: div, first, lines: lines.slice(first, first + SOURCE_BLOCK), rows: null };
    div.block = block;
    div.textContent = block.lines.join('\n') + '\n';
    // A block out of view keeps the height of its lines (one line each: the text does not wrap).
    div.style.containIntrinsicSize = `auto ${(block.lines.length * 1.4).toFixed(1)}em`;
    pre.appendChild(div);
    S.sourceBlocks.push(block);
    S.sourceObserver.observe(div);
  }
  fillBlock(S.sourceBlocks[0]);  // the top is in view: numbered at once
}

// A block's element per line, with its highlights as they are now.
function fillBlock(block) {
  if (!block || block.rows) return;
  block.rows = block.lines.map((line, k) => {
    const n = block.first + k + 1, row = el('span', 'src-line');
    row.dataset.line = String(n);
    row.appendChild(el('span', 'ln', String(n)));
    row.appendChild(document.createTextNode(line));
    if (S.activeLines.has(n)) row.classList.add('active');
    if (S.selectedLine === n) row.classList.add('selected');
    return row;
  });
  block.el.textContent = '';
  block.el.append(...block.rows);
}

// Line n's element, when its block has them (`fill`: give it them now).
function sourceRow(n, fill) {
  const block = (S.sourceBlocks || [])[Math.floor((n - 1) / SOURCE_BLOCK)];
  if (!block || n < 1) return null;
  if (fill) fillBlock(block);
  return block.rows ? block.rows[(n - 1) % SOURCE_BLOCK] || null : null;
}

// Only the rows whose state changed are touched: a generated mission has tens of thousands.
function renderSourceActive() {
  const active = new Set();
  for (const b of D.bars) if (b.start <= S.clock + 1e-9 && (b.end === null || b.end > S.clock + 1e-9)) active.add(b.line);
  const before = S.activeLines || new Set();
  S.activeLines = active;  // a block filled later takes its highlights from here
  for (const line of before) if (!active.has(line)) { const r = sourceRow(line); if (r) r.classList.remove('active'); }
  for (const line of active) if (!before.has(line)) { const r = sourceRow(line); if (r) r.classList.add('active'); }
}

function select(what) {
  S.selected = what;
  const nodes = new Set(what.nodes || []);
  const sameBar = b => (nodes.size ? b.nodes.some(n => nodes.has(n)) : b.line === what.line && b.drone === what.drone);
  for (const b of D.bars) if (b.el) b.el.classList.toggle('selected', sameBar(b));
  for (const c of D.conds) if (c.el) c.el.classList.toggle('selected', nodes.size ? c.nodes.some(n => nodes.has(n)) : c.line === what.line);
  for (const g of $('graph').querySelectorAll('g.node')) g.classList.toggle('selected', nodes.has(Number(g.dataset.node)));
  const before = sourceRow(S.selectedLine || 0);
  if (before) before.classList.remove('selected');
  S.selectedLine = what.line > 0 ? what.line : 0;
  const lineRow = sourceRow(S.selectedLine, true);
  if (lineRow) lineRow.classList.add('selected');
  if (lineRow) lineRow.scrollIntoView({ block: 'nearest' });
  const g = $('graph').querySelector('g.node.selected');
  if (g) bringIntoView(g);
  const sel = $('selection');
  sel.textContent = selectionText(what, nodes);
  sel.dataset.line = String(what.line || '');
  sel.dataset.node = [...nodes].join(' ');
  sel.dataset.outcome = what.outcome || '';
  sel.dataset.reason = what.reason || '';
}

// "Drone2.FlyByX(40) — failed: timed out after 2.0 s — 1.65 s to 3.65 s — line 8 — MEG node 9"
function selectionText(what, nodes) {
  const parts = [];
  if (what.prefix) parts.push(what.prefix + ':');
  parts.push(what.text || '');
  if (what.outcome) parts.push('— ' + what.outcome + (what.reason ? ': ' + what.reason : ''));
  if (typeof what.t === 'number')
    parts.push('— ' + (typeof what.end === 'number' ? `${what.t.toFixed(2)} s to ${what.end.toFixed(2)} s`
                                                     : `at ${what.t.toFixed(2)} s`));
  if (what.line) parts.push('— line ' + what.line);
  if (nodes.size) parts.push('— MEG node ' + [...nodes].join(', '));
  return parts.join(' ');
}

// ---- the connection ----

function onMessage(text) {
  let m;
  try { m = JSON.parse(text); } catch (e) { return; }
  if (!m || typeof m !== 'object') return;
  if (m.type === 'mission') {
    S.mission = m.mission && typeof m.mission === 'object' ? m.mission : {};
    S.live = !!S.mission.live;
    S.finished = false;
    S.events = [];
    S.undrawn = [];
    S.latencies = [];
    S.arrivals = [];
    S.serverDelays = [];
    S.liveFrom = Infinity;
    S.historyIn = false;
    if (S.historyFrame) cancelAnimationFrame(S.historyFrame);
    S.historyFrame = 0;
    resetDerived();
    $('mission-name').textContent = str(S.mission.mission);
    buildSource();
    buildGraphSelect();
    S.structureDirty = true;
  } else if (m.type === 'events' && Array.isArray(m.events) && D) {
    for (const e of m.events) { S.events.push(e); ingest(e); }
    document.body.dataset.events = String(S.events.length);
    if (Array.isArray(m.emitted)) {
      const arrived = wallNow();
      for (const emitted of m.emitted) {
        if (typeof emitted !== 'number' || emitted < S.liveFrom) continue;
        S.undrawn.push(emitted);
        S.arrivals.push(arrived - emitted);
        if (typeof m.sent === 'number') S.serverDelays.push(m.sent - emitted);
      }
      if (S.arrivals.length > LATENCIES_MAX) S.arrivals.splice(0, S.arrivals.length - LATENCIES_MAX);
      if (S.serverDelays.length > LATENCIES_MAX) S.serverDelays.splice(0, S.serverDelays.length - LATENCIES_MAX);
      S.historyIn = true;
    }
    // A page in a background tab gets no animation frames: keep its DOM current anyway.
    if (document.hidden) { if (S.live && !S.finished && S.follow) S.clock = missionEnd(); render(); }
  } else if (m.type === 'finished') {
    const first = !S.finished;
    if (S.live && S.follow) S.clock = missionEnd();  // every event is in: follow it to the end
    S.finished = true;
    const start = new URLSearchParams(location.search).get('t');
    if (start !== null) { S.playing = false; setClock(Number(start)); }
    else if (first && !S.live) { setClock(0); S.playing = true; }
    // Drawn before it says so: whoever waits for data-finished (a test) reads the finished page.
    render();
    document.body.dataset.finished = 'true';
  }
}

function connect() {
  const ws = new WebSocket((location.protocol === 'https:' ? 'wss://' : 'ws://') + location.host + '/ws');
  ws.onopen = () => { $('connection').dataset.state = 'open'; $('connection').textContent = ''; ws.send('hello'); };
  ws.onmessage = ev => { if (typeof ev.data === 'string') onMessage(ev.data); };
  ws.onclose = () => {
    $('connection').dataset.state = 'closed';
    $('connection').textContent = S.finished ? '' : 'disconnected; retrying…';
    if (!S.finished) setTimeout(connect, 1000);
  };
}

function wireControls() {
  $('play').onclick = () => { if (S.clock >= missionEnd()) setClock(0); S.playing = true; S.follow = false; $('follow').checked = false; S.dirty = true; };
  $('pause').onclick = () => { S.playing = false; S.dirty = true; };
  $('speed').onchange = e => { S.speed = Number(e.target.value) || 1; };
  $('scrub').oninput = e => { S.follow = false; $('follow').checked = false; setClock(Number(e.target.value)); };
  $('next-event').onclick = () => { const t = nextEventTime(S.clock); if (t !== null) { S.follow = false; $('follow').checked = false; setClock(t); } };
  $('next-failure').onclick = () => jumpToFailure(1);
  $('prev-failure').onclick = () => jumpToFailure(-1);
  $('banner-show').onclick = () => { if (S.bannerFailure) showFailure(S.bannerFailure, 'the failure'); };
  wireGraphView();
  $('follow').onchange = e => { S.follow = e.target.checked; S.dirty = true; };
  // A control's effect shows at once, not at the next animation frame.
  for (const id of ['play', 'pause', 'scrub', 'next-event', 'next-failure', 'prev-failure', 'banner-show', 'follow'])
    $(id).addEventListener(id === 'scrub' ? 'input' : 'click', () => render());
  $('graph-select').onchange = e => showGraph(Number(e.target.value));
  window.addEventListener('resize', () => { S.dirty = true; });
  document.addEventListener('keydown', e => {
    if (e.key === ' ' && e.target === document.body) { e.preventDefault(); (S.playing ? $('pause') : $('play')).click(); }
  });
}

// For the browser tests and for people at the console: read-only views of the page's state.
window.eamosMonitor = {
  setClock: t => { S.playing = false; S.follow = false; $('follow').checked = false; setClock(t); render(); },
  clock: () => S.clock,
  nodeState: id => stateAt(id),
  // Live events: ms from eamos emitting one to this page having drawn it (see noteDrawn), and
  // to its arrival here (the part the network and the server take).
  liveLatency: () => latencyStats(S.latencies),
  // The same for the first n live events only (the page catching up after it drew its history).
  firstLiveLatency: n => latencyStats(S.latencies.slice(0, n)),
  // ms from navigation to the end of the page's first frame with the history (null before).
  liveSince: () => (S.liveFrom === Infinity ? null : S.liveFrom - performance.timeOrigin),
  arrivalLatency: () => latencyStats(S.arrivals),
  serverLatency: () => latencyStats(S.serverDelays),
  // How long each render took, ms (the page's own work per frame).
  renderTimes: () => latencyStats(S.renderTimes),
  // Large fleets: the lanes canvas's renders, the columns they drew in all, and how many it has.
  laneColumns: () => ({ ...S.laneColumns }),
  // The drones marked failed on the map and in their lanes at the clock.
  failedDrones: () => D.drones.filter(d => failedBy(d.name, S.clock)).map(d => d.name),
  triggers: () => (D.triggerList || []).map(t => ({ from: t.from, to: t.to, sent: t.sent, received: t.received, wait: t.received - t.waitFrom })),
};

resetDerived();
wireControls();
connect();
requestAnimationFrame(tick(performance.now()));
