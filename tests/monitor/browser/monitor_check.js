// Drives Debian's chromium headless against a running `eamos monitor` / `eamos run --monitor`
// and checks what the page shows, through its DOM. Called by tests/monitor/browser_test.cpp:
//   node monitor_check.js replay|live|live20|live1000|launch|v1|scale|violation|failed|waits|giveway|palette URL SCREENSHOT_DIR CHROMIUM
// Prints "ok: ..." lines and exits 0, or prints "FAIL: what" and exits 1.
'use strict';
const fs = require('fs');
const os = require('os');
const path = require('path');
const puppeteer = require('puppeteer-core');

const [mode, url, shots, chromium] = process.argv.slice(2);
const failures = [];
function check(ok, what) {
  if (ok) console.log('ok: ' + what); else { console.log('FAIL: ' + what); failures.push(what); }
}

async function launch() {
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'eamos-chromium-'));
  const browser = await puppeteer.launch({
    executablePath: chromium, userDataDir: profile, headless: true,
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
           '--disable-background-networking', '--disable-component-update', '--disable-sync'],
  });
  return { browser, profile };
}

async function open(browser, query) {
  const page = await browser.newPage();
  page.on('pageerror', e => failures.push('page error: ' + e.message));
  await page.setViewport({ width: 1600, height: 1000 });
  await page.goto(url + (query || ''));
  return page;
}

// Everything the assertions need, read from the DOM at the page's clock.
function snapshot() {
  const bars = [...document.querySelectorAll('.bar')].map(b => ({
    drone: b.dataset.drone, name: b.dataset.name, line: Number(b.dataset.line), outcome: b.dataset.outcome,
    state: b.dataset.state, start: Number(b.dataset.start) }));
  const conds = [...document.querySelectorAll('.cond')].map(c => ({
    drone: c.dataset.drone, name: c.dataset.name, value: c.dataset.value, label: c.textContent, future: c.classList.contains('future') }));
  const triggers = [...document.querySelectorAll('#triggers .trigger')].map(t => ({
    from: t.dataset.from, to: t.dataset.to, sent: Number(t.dataset.sent), received: Number(t.dataset.received),
    wait: Number(t.dataset.wait) }));
  const nodes = {};
  for (const g of document.querySelectorAll('#graph g.node[data-node]')) {
    const label = [...g.querySelectorAll('text')].map(t => t.textContent).join(' ');
    nodes[label] = g.dataset.state;
  }
  return { lanes: [...document.querySelectorAll('.lane')].map(l => l.dataset.drone), bars, conds, triggers, nodes,
           clock: Number(document.getElementById('clock').dataset.t), outcome: document.getElementById('outcome').dataset.outcome,
           mode: document.getElementById('mode').dataset.mode, events: Number(document.body.dataset.events || 0),
           drones: [...document.querySelectorAll('#drone-list li')].map(li => li.dataset.drone) };
}

function nodeState(snap, text) {
  const key = Object.keys(snap.nodes).find(k => k.includes(text));
  return key ? snap.nodes[key] : undefined;
}
function bar(snap, drone, name) { return snap.bars.filter(b => b.drone === drone && b.name === name); }

async function replay(browser) {
  const page = await open(browser, '?t=5');
  await page.waitForSelector('body[data-finished="true"]', { timeout: 15000, polling: 100 });
  await page.evaluate(() => window.eamosMonitor.setClock(1e9));
  let s = await page.evaluate(snapshot);
  check(JSON.stringify(s.lanes) === '["Drone1","Drone2","Drone3"]', 'three lanes, Drone1 to Drone3: ' + s.lanes);
  check(s.outcome === 'completed', 'the mission completed: ' + s.outcome);
  const d1 = s.bars.filter(b => b.drone === 'Drone1').map(b => b.name + ':' + b.outcome).join(' ');
  check(d1 === 'Arm:succeeded Takeoff:succeeded FlyByX:succeeded Land:succeeded Disarm:succeeded',
        'Drone1 took the else branch of the If (Takeoff(4), FlyByX(-5)), every action succeeded: ' + d1);
  check(bar(s, 'Drone1', 'Takeoff')[0] && bar(s, 'Drone1', 'Takeoff')[0].line === 85, 'Drone1 Takeoff is line 85 (SEQ_go_left)');
  const orbit = bar(s, 'Drone2', 'Orbit');
  check(orbit.length === 1 && orbit[0].outcome === 'preempted', 'Drone2 Orbit was preempted (by Land)');
  check(bar(s, 'Drone2', 'TakePicture').length === 2 && bar(s, 'Drone2', 'TakePicture').every(b => b.outcome === 'succeeded'),
        'Drone2 took two pictures while the RepeatWhile held');
  const d3 = s.bars.filter(b => b.drone === 'Drone3').map(b => b.name).join(' ');
  check(d3 === 'Arm Takeoff Sensor2 FlyByX Land Disarm', 'Drone3 flew after the WaitUntil: ' + d3);
  const ifMark = s.conds.find(c => c.drone === 'Drone1' && c.name === 'If');
  check(ifMark && ifMark.value === 'false' && ifMark.label.includes('If'), 'the If is labelled with its outcome (false)');
  const waits = s.conds.filter(c => c.name === 'WaitUntil').map(c => c.value).join(',');
  check(waits === 'false,true', 'the WaitUntil marks: false at the start, then true: ' + waits);
  const trigger = s.triggers.find(t => t.from === 'Drone1' && t.to === 'Drone3');
  check(trigger && Math.abs(trigger.sent - 3.75) < 1e-6 && Math.abs(trigger.received - 3.75) < 1e-6,
        'an arrow from Drone1 (its WaitUntil held at 3.75 s) to Drone3');
  check(trigger && Math.abs(trigger.wait - 3.75) < 0.01, 'Drone3 waited 3.75 s on Drone1: ' + (trigger && trigger.wait));

  await page.evaluate(() => window.eamosMonitor.setClock(5));
  s = await page.evaluate(snapshot);
  check(Math.abs(s.clock - 5) < 1e-6, 'the clock is at 5 s');
  const expect = { 'Drone1.Land()': 'running', 'Drone1.Takeoff(4)': 'succeeded', 'Drone1.FlyByX(-5)': 'succeeded',
                   'Drone1.Takeoff(3)': 'waiting', 'If Drone1.Sensor1()': 'false', 'WaitUntil Drone1.X()': 'true',
                   'Drone3.Takeoff(3)': 'running', 'Drone2.Orbit()': 'running', 'Drone3.FlyByX(': 'waiting',
                   'Drone2.Land()': 'waiting', 'Drone1.Arm()': 'succeeded' };
  for (const [text, state] of Object.entries(expect))
    check(nodeState(s, text) === state, `MEG node ${text} is ${state} at 5 s: ${nodeState(s, text)}`);
  check(bar(s, 'Drone1', 'Land')[0].state === 'running' && bar(s, 'Drone3', 'FlyByX')[0].state === 'future',
        'at 5 s Drone1 lands and Drone3 has not started its FlyByX');
  check(s.drones.length === 3, 'the map lists three drones');
  await page.screenshot({ path: path.join(shots, 'replay-listing2-t5.png'), fullPage: true });

  await graphZoomAndPan(page);

  // Selecting Drone1's Land in its lane selects its node and its source line.
  await page.click('.bar[data-drone="Drone1"][data-name="Land"]');
  const sel = await page.evaluate(() => ({
    line: document.querySelector('.src-line.selected') && document.querySelector('.src-line.selected').dataset.line,
    node: [...document.querySelectorAll('#graph g.node.selected')].map(g => g.textContent).join(' ') }));
  check(sel.line === '42', 'clicking Drone1 Land selects source line 42: ' + sel.line);
  check(sel.node.includes('Drone1.Land()'), 'and its MEG node');

  // The controls: next event from 5 s is Drone3's Takeoff end at 5.4 s; play moves the clock.
  await page.click('#next-event');
  s = await page.evaluate(snapshot);
  check(Math.abs(s.clock - 5.4) < 1e-6, 'next event jumps to 5.4 s: ' + s.clock);
  await page.select('#speed', '16');
  await page.click('#play');
  await page.waitForFunction(() => Number(document.getElementById('clock').dataset.t) > 6, { timeout: 10000, polling: 100 });
  check(true, 'play advances the clock');
  await page.close();
}

// The graph panel: the buttons and the wheel zoom around a point, a drag pans, "fit" shows it whole.
async function graphZoomAndPan(page) {
  const view = () => page.evaluate(() => {
    const [x, y, w, h] = document.getElementById('graph-svg').getAttribute('viewBox').split(/\s+/).map(Number);
    return { x, y, w, h };
  });
  const v0 = await view();
  await page.click('#zoom-in');
  const v1 = await view();
  check(Math.abs(v1.w - v0.w / 1.5) < 0.01 * v0.w, `"+" zooms in 1.5× (${v0.w.toFixed(0)} → ${v1.w.toFixed(0)} wide)`);
  const box = await page.evaluate(() => { const r = document.getElementById('graph').getBoundingClientRect();
                                          return { x: r.left, y: r.top, w: r.width, h: r.height }; });
  await page.mouse.move(box.x + box.w / 2, box.y + box.h / 2);
  await page.mouse.wheel({ deltaY: -400 });
  await page.waitForFunction(w => Number(document.getElementById('graph-svg').getAttribute('viewBox').split(/\s+/)[2]) < w,
                             { timeout: 5000, polling: 50 }, v1.w);
  const v2 = await view();
  check(v2.w < v1.w, `the wheel zooms in further (${v1.w.toFixed(0)} → ${v2.w.toFixed(0)} wide)`);
  await page.mouse.down();
  for (let i = 1; i <= 5; i++) await page.mouse.move(box.x + box.w / 2 - 20 * i, box.y + box.h / 2 - 10 * i);
  await page.mouse.up();
  const v3 = await view();
  const scale = v2.w / box.w;
  check(Math.abs(v3.x - v2.x - 100 * scale) < 2 * scale && Math.abs(v3.y - v2.y - 50 * scale) < 2 * scale,
        `a drag of 100 × 50 px pans the view with the pointer (x ${v2.x.toFixed(1)} → ${v3.x.toFixed(1)})`);
  await page.click('#zoom-fit');
  const fitted = await page.evaluate(() => {
    const box = document.getElementById('graph').getBoundingClientRect();
    const nodes = [...document.querySelectorAll('#graph g.node')].map(g => g.getBoundingClientRect());
    return { count: nodes.length, inside: nodes.every(r => r.left >= box.left - 1 && r.right <= box.right + 1 &&
                                                            r.top >= box.top - 1 && r.bottom <= box.bottom + 1) };
  });
  check(fitted.count > 20 && fitted.inside, `"fit" shows all ${fitted.count} nodes in the panel`);
  await page.screenshot({ path: path.join(shots, 'replay-listing2-graph-fit.png') });
}

// A schema v1 trace: the mission comes from its header, positions from its telemetry, the
// arrows from its message events (tests/monitor/browser_test.cpp writes it).
async function v1(browser) {
  const page = await open(browser, '?t=4');
  await page.waitForSelector('body[data-finished="true"]', { timeout: 15000, polling: 100 });
  const s = await page.evaluate(snapshot);
  check(Object.keys(s.nodes).length > 20, 'the graph comes from the header\'s mission: ' + Object.keys(s.nodes).length + ' nodes');
  const note = await page.evaluate(() => document.getElementById('map-note').textContent);
  check(note === '', 'the map has telemetry: "' + note + '"');
  const d1 = await page.evaluate(() => {
    const li = document.querySelector('#drone-list li[data-drone="Drone1"]');
    return li ? Number(li.dataset.x) : NaN; });
  check(Math.abs(d1 - -4) < 0.01, 'at 4 s Drone1 is at x = -4 (interpolated telemetry): ' + d1);
  const t = s.triggers.filter(t => t.from === 'Drone1' && t.to === 'Drone3');
  check(t.length === 1 && Math.abs(t[0].sent - 3.7) < 1e-6 && Math.abs(t[0].received - 3.75) < 1e-6,
        'the Drone1 → Drone3 arrow is the message event (sent 3.7, received 3.75)');
  const source = await page.evaluate(() => document.querySelectorAll('#source .src-line').length);
  check(source > 90, 'the mission text is the header\'s: ' + source + ' lines');
  await page.screenshot({ path: path.join(shots, 'replay-v1-header-t4.png'), fullPage: true });
}

// `eamos verify --trace` of separation.eamos: one red mark in Drone1's lane at 3.75 s, its
// diagnostic as the title, and "next failure" stops there.
async function violation(browser) {
  const page = await open(browser, '?t=0');
  await page.waitForSelector('body[data-finished="true"]', { timeout: 15000, polling: 100 });
  const marks = await page.evaluate(() => [...document.querySelectorAll('.violation')].map(m => ({
    lane: m.closest('.lane') ? m.closest('.lane').dataset.drone : '', drone: m.dataset.drone, kind: m.dataset.kind,
    line: Number(m.dataset.line), t: Number(m.dataset.t), title: m.title,
    colour: getComputedStyle(m).backgroundColor })));
  check(marks.length === 1, 'one violation mark: ' + JSON.stringify(marks));
  const m = marks[0] || {};
  check(m.lane === 'Drone1' && m.drone === 'Drone1', 'the mark is in Drone1\'s lane: ' + m.lane);
  check(m.kind === 'separation' && m.line === 8 && Math.abs(m.t - 3.75) < 1e-9, 'separation at line 8, 3.75 s');
  check((m.title || '').includes('come within 1.88 m') && (m.title || '').includes('Drone2'),
        'its title is the diagnostic: ' + m.title);
  check(m.colour === 'rgb(213, 0, 0)', 'the mark is red: ' + m.colour);
  await page.click('#next-failure');
  const clock = await page.evaluate(() => Number(document.getElementById('clock').dataset.t));
  check(Math.abs(clock - 3.75) < 1e-6, '"next failure" stops at the violation: ' + clock);
  // It says what it is: a verification with one violation, not a green "mission completed".
  const head = await page.evaluate(() => ({
    mode: document.getElementById('mode').dataset.mode, modeText: document.getElementById('mode').textContent,
    outcome: document.getElementById('outcome').dataset.outcome, outcomeText: document.getElementById('outcome').textContent,
    banner: document.getElementById('banner').hidden ? '' : document.getElementById('banner-text').textContent,
    note: document.getElementById('map-note').textContent,
    d1: (() => { const li = document.querySelector('#drone-list li[data-drone="Drone1"]');
                 return li ? { x: Number(li.dataset.x), y: Number(li.dataset.y), z: Number(li.dataset.z) } : null; })() }));
  check(head.mode === 'verify' && head.modeText.includes('verify'), 'the header says it is a verify run: ' + head.modeText);
  check(head.outcome === 'violations' && head.outcomeText === '1 violation', 'and that it found 1 violation: ' + head.outcomeText);
  check(!head.outcomeText.includes('completed'), 'no "mission completed"');
  check(head.banner.includes('Verification run (path 1 of 1 flown): 1 violation') && head.banner.includes('separation at 3.75 s'),
        'the banner names the path and the first violation: ' + head.banner);
  check(head.note === '', 'the map has positions: "' + head.note + '"');
  check(head.d1 && head.d1.y > 2 && head.d1.y < 8 && Math.abs(head.d1.z - 5) < 0.2,
        'at 3.75 s Drone1 is on its way at 5 m, not at its home: ' + JSON.stringify(head.d1));
  await page.screenshot({ path: path.join(shots, 'replay-verify-separation.png'), fullPage: true });
}

// 1,000 drones: lanes on a canvas, no element per bar, and a change of the clock redrawn fast.
async function scale(browser) {
  const page = await open(browser, '?t=0');
  await page.waitForSelector('body[data-finished="true"]', { timeout: 60000, polling: 200 });
  const r = await page.evaluate(() => {
    const start = performance.now();
    for (let i = 1; i <= 10; i++) window.eamosMonitor.setClock(i * 4);
    const perRender = (performance.now() - start) / 10;
    const canvas = document.getElementById('lanes-canvas');
    return { perRender, bars: document.querySelectorAll('.bar').length, canvasHidden: canvas.hidden,
             drones: Number(canvas.dataset.drones), drawn: Number(canvas.dataset.bars),
             elements: document.querySelectorAll('#timeline-panel *').length };
  });
  check(r.drones === 1000 && !r.canvasHidden && r.drawn > 1000, `1000 lanes on the canvas (${r.drawn} bars drawn)`);
  check(r.bars === 0 && r.elements < 100, `no element per bar (${r.elements} elements in the timeline)`);
  // Generous for two shared cores: a frame budget is 16 ms, a person notices a stall at about 0.5 s.
  check(r.perRender < 500, `a clock change redraws in ${r.perRender.toFixed(1)} ms`);
  // The mission text: every line in the page as text, numbered lines only near the view (an
  // element per line of 20,000 would be built, styled and laid out), and the end numbered
  // once it is scrolled to.
  const text = await page.evaluate(() => {
    const source = document.getElementById('source');
    return { far: source.textContent.includes('var D999 Quad'), rows: source.querySelectorAll('.src-line').length,
             blocks: source.querySelectorAll('.src-block').length };
  });
  check(text.far && text.rows > 0 && text.rows < 2000 && text.blocks > 50,
        `the mission text is all in the page, ${text.rows} lines of it numbered (${text.blocks} blocks)`);
  await page.evaluate(() => { const s = document.getElementById('source'); s.scrollTop = s.scrollHeight; });
  const end = await page.waitForFunction(() => {
    const rows = document.querySelectorAll('#source .src-block:last-child .src-line');
    return rows.length ? Number(rows[rows.length - 1].dataset.line) : 0;
  }, { timeout: 10000, polling: 100 }).then(h => h.jsonValue(), () => 0);
  check(end > 200 * (text.blocks - 1), `scrolled to its end, the mission text numbers its last line (${end})`);
  await page.screenshot({ path: path.join(shots, 'replay-1000-drones.png') });
}

// Each drone's colour as the page draws it (its swatch in the drone list), printed as one
// "colours: {...}" line of JSON for the test to compare with the SVGs eamos writes.
async function palette(browser) {
  const page = await open(browser, '');
  await page.waitForSelector('body[data-finished="true"]', { timeout: 15000, polling: 100 });
  await page.evaluate(() => window.eamosMonitor.setClock(1e9));
  const colours = await page.evaluate(() => {
    const hex = rgb => '#' + (rgb.match(/\d+/g) || []).slice(0, 3).map(v => Number(v).toString(16).padStart(2, '0'))
      .join('').toUpperCase();
    const out = {};
    for (const li of document.querySelectorAll('#drone-list li'))
      out[li.dataset.drone] = hex(getComputedStyle(li.querySelector('.swatch')).backgroundColor);
    return out;
  });
  check(Object.keys(colours).length === 20, `20 drones in the list (${Object.keys(colours).length})`);
  console.log('colours: ' + JSON.stringify(colours));
}

async function live(browser) {
  const page = await open(browser, '');
  await page.waitForFunction(() => document.querySelectorAll('.lane').length === 3, { timeout: 15000, polling: 100 });
  let s = await page.evaluate(snapshot);
  check(s.mode === 'live' || s.outcome === '', 'the page says live while the mission flies: ' + s.mode);
  const firstEvents = s.events;
  await page.waitForFunction(n => Number(document.body.dataset.events || 0) > n, { timeout: 30000, polling: 100 }, firstEvents);
  s = await page.evaluate(snapshot);
  check(s.events > firstEvents, `new events arrived live (${firstEvents} then ${s.events})`);
  await page.screenshot({ path: path.join(shots, 'live-listing2-during.png'), fullPage: true });

  // A second browser and a reload get the history so far, then the live events.
  const second = await open(browser, '');
  await second.waitForFunction(n => Number(document.body.dataset.events || 0) >= n, { timeout: 15000, polling: 100 }, s.events);
  check(true, 'a second page got the history so far');
  // Polling, not animation frames: a page in a background tab draws no frames.
  await page.bringToFront();
  await page.reload();
  await page.waitForFunction(() => document.body.dataset.finished === 'true', { timeout: 60000, polling: 100 });
  await second.waitForFunction(() => document.body.dataset.finished === 'true', { timeout: 60000, polling: 100 });
  const a = await page.evaluate(snapshot), b = await second.evaluate(snapshot);
  check(a.outcome === 'completed' && b.outcome === 'completed', 'both pages saw the mission complete');
  check(a.events === b.events && a.events > 40, `the reloaded page and the second page have every event (${a.events}, ${b.events})`);
  check(a.triggers.some(t => t.from === 'Drone1' && t.to === 'Drone3'), 'the live page draws the Drone1 → Drone3 trigger');
  const l = await second.evaluate(() => window.eamosMonitor.liveLatency());
  console.log(`info: ${l.count} live events drawn; emitted to drawn: median ${ms(l.median)}, p95 ${ms(l.p95)}, max ${ms(l.max)}`);
  await page.screenshot({ path: path.join(shots, 'live-listing2-end.png'), fullPage: true });
}

function ms(v) { return v === null ? '?' : v.toFixed(1) + ' ms'; }

// 20 drones live in real time, telemetry at the default rate: events drawn within 100 ms of
// eamos emitting them (p95), in the page that stays in front and follows the mission. 800
// live events (about 8 s of the flight) are enough; the test then stops the run.
async function live20(browser) {
  const page = await open(browser, '');
  await page.waitForFunction(() => window.eamosMonitor.liveLatency().count >= 800, { timeout: 60000, polling: 200 });
  const s = await page.evaluate(snapshot);
  check(s.lanes.length === 20 && s.mode === 'live', `20 lanes of a live mission (${s.lanes.length}, ${s.mode})`);
  const l = await page.evaluate(() => window.eamosMonitor.liveLatency());
  const a = await page.evaluate(() => window.eamosMonitor.arrivalLatency());
  const v = await page.evaluate(() => window.eamosMonitor.serverLatency());
  console.log(`info: ${l.count} live events; emitted to drawn: median ${ms(l.median)}, p95 ${ms(l.p95)}, max ${ms(l.max)}`);
  console.log(`info: emitted to arrived: median ${ms(a.median)}, p95 ${ms(a.p95)}, max ${ms(a.max)}; ` +
              `to sent by the server: median ${ms(v.median)}, p95 ${ms(v.p95)}, max ${ms(v.max)}`);
  console.log(`info: load average ${os.loadavg().map(x => x.toFixed(1)).join(' ')} on ${os.cpus().length} cores`);
  check(l.p95 !== null && l.p95 < 100, `p95 of emitted-to-drawn below 100 ms: ${ms(l.p95)}`);
  await page.screenshot({ path: path.join(shots, 'live-20-drones.png') });
}

// CPU that processes outside this test used while it measured, as a share of the machine:
// the jiffies /proc/stat counts busy, less those of the test's own processes (the gtest
// binary EAMOS_TEST_PID names and everything under it: eamos, node, Chromium). A process of
// the test that ends inside the window counts as other work, which errs toward skipping.
function cpuTicks(root) {
  const cpu = fs.readFileSync('/proc/stat', 'utf8').split('\n')[0].trim().split(/\s+/).slice(1).map(Number);
  const total = cpu.slice(0, 8).reduce((a, b) => a + b, 0);
  const busy = total - cpu[3] - cpu[4];  // less idle and iowait
  const parent = new Map(), ticks = new Map();
  for (const d of fs.readdirSync('/proc')) {
    if (!/^\d+$/.test(d)) continue;
    try {
      const text = fs.readFileSync(`/proc/${d}/stat`, 'utf8');
      const f = text.slice(text.lastIndexOf(')') + 2).split(' ');
      parent.set(Number(d), Number(f[1]));
      ticks.set(Number(d), Number(f[11]) + Number(f[12]));
    } catch (e) { /* the process ended meanwhile */ }
  }
  let own = 0;
  for (const [pid, t] of ticks) {
    let p = pid;
    for (let hops = 0; p > 1 && p !== root && hops < 64; ++hops) p = parent.get(p) || 0;
    if (p === root) own += t;
  }
  return { total, busy, own };
}

function otherWork(before, after) {
  const total = after.total - before.total;
  return total > 0 ? Math.max(0, (after.busy - before.busy) - (after.own - before.own)) / total : 0;
}

// A large fleet live at high speed (lanes on a canvas; `drones` of them): p95 of
// emitted-to-drawn below `bound` ms over the first `events` live events (telemetry included). Prints the
// page's render times. The test stops the run after.
async function liveScale(browser, drones, bound, events) {
  const root = Number(process.env.EAMOS_TEST_PID) || process.ppid;
  const ticksBefore = cpuTicks(root);
  const page = await open(browser, '');
  await page.waitForFunction(n => window.eamosMonitor.liveLatency().count >= n, { timeout: 90000, polling: 200 }, events);
  const others = otherWork(ticksBefore, cpuTicks(root));
  const r = await page.evaluate(() => {
    const canvas = document.getElementById('lanes-canvas');
    return { drones: Number(canvas.dataset.drones), hidden: canvas.hidden, mode: document.getElementById('mode').dataset.mode,
             frames: window.eamosMonitor.renderTimes(), events: Number(document.body.dataset.events || 0) };
  });
  check(r.drones === drones && !r.hidden, `${drones} lanes on the canvas (${r.drones})`);
  check(r.mode === 'live' || r.mode === 'ended', `a live mission (${r.mode})`);
  const l = await page.evaluate(() => window.eamosMonitor.liveLatency());
  const a = await page.evaluate(() => window.eamosMonitor.arrivalLatency());
  const v = await page.evaluate(() => window.eamosMonitor.serverLatency());
  const f = await page.evaluate(() => ({ first: window.eamosMonitor.firstLiveLatency(2000), since: window.eamosMonitor.liveSince() }));
  console.log(`info: ${l.count} live events of ${r.events}; emitted to drawn: median ${ms(l.median)}, p95 ${ms(l.p95)}, max ${ms(l.max)}`);
  console.log(`info: history drawn ${ms(f.since)} after navigation; the first 2,000 live events: median ${ms(f.first.median)}, ` +
              `p95 ${ms(f.first.p95)}, max ${ms(f.first.max)}`);
  console.log(`info: emitted to arrived: median ${ms(a.median)}, p95 ${ms(a.p95)}, max ${ms(a.max)}; ` +
              `to sent by the server: median ${ms(v.median)}, p95 ${ms(v.p95)}, max ${ms(v.max)}`);
  console.log(`info: renders: ${r.frames.count}, median ${ms(r.frames.median)}, p95 ${ms(r.frames.p95)}, max ${ms(r.frames.max)}`);
  console.log(`info: load average ${os.loadavg().map(x => x.toFixed(1)).join(' ')} on ${os.cpus().length} cores`);
  console.log(`info: other work used ${(100 * others).toFixed(0)} % of the machine while the test measured`);
  // The bounds are the page's on a host with cores for it. Other work beside it delays
  // Chromium's processes more than the page's script: in real time at load 15-53 on 2 cores
  // the p95 was 190-800 ms with renders of 2-5 ms. A miss while other processes took more
  // than a quarter of the machine is reported and skipped, not failed; on a host left to the
  // test it fails.
  const timed = (held, what) => {
    if (!held && others > 0.25) console.log(`skip: ${what}, while other work used ${(100 * others).toFixed(0)} % of the machine`);
    else check(held, what);
  };
  timed(l.p95 !== null && l.p95 < bound, `p95 of emitted-to-drawn below ${bound} ms: ${ms(l.p95)}`);
  // The page's own work (2.4-5.0 ms in real time at load 4-40): half a frame at most.
  timed(r.frames.median !== null && r.frames.median < 8, `the page renders in under 8 ms: ${ms(r.frames.median)} (median)`);
  // Read after the latencies: reading the canvases back takes the page's thread a while.
  // The lanes' picture is kept from frame to frame and a render draws only the columns that
  // changed: the bars that started or ended and the running bars' growth near the clock.
  const c = await page.evaluate(() => window.eamosMonitor.laneColumns());
  const perRender = c.drawn / Math.max(1, c.renders);
  console.log(`info: lanes: ${c.renders} renders drew ${c.drawn} of their ${c.columns} columns (${perRender.toFixed(2)} a render)`);
  check(c.renders > 10 && perRender < c.columns / 2, `a render draws few of the lanes' columns (${perRender.toFixed(2)} of ${c.columns})`);
  // ... and what it keeps is the picture drawn afresh at the same clock: the same pixels but
  // for the edges of bars drawn in steps (anti-aliasing).
  const same = await page.evaluate(() => {
    const pixels = () => [...document.querySelectorAll('#lanes-canvas canvas')].map(c =>
      c.getContext('2d').getImageData(0, 0, c.width, c.height).data);
    renderLanesCanvas();
    const kept = pixels();
    S.laneTiles = null;
    renderLanesCanvas();
    const fresh = pixels();
    let painted = 0, differ = 0;
    kept.forEach((k, i) => {
      const f = fresh[i];
      for (let p = 0; p < k.length; p += 4) {
        if (k[p + 3] || f[p + 3]) painted++;
        let d = 0;
        for (let q = 0; q < 4; q++) d += Math.abs(k[p + q] - f[p + q]);
        if (d > 96) differ++;
      }
    });
    return { painted, differ };
  });
  check(same.painted > 0 && same.differ <= same.painted * 0.01,
        `the kept lanes are the picture drawn afresh: ${same.differ} of ${same.painted} painted pixels differ`);
  await page.screenshot({ path: path.join(shots, `live-${drones}-drones.png`) });
}

// `eamos launch DIR --monitor`: the ground's events of a deployment's DEX processes reach the
// page live and it ends with the mission, its graphs from the manifest's source.
async function launchLive(browser) {
  const page = await open(browser, '');
  await page.waitForFunction(() => document.querySelectorAll('.lane').length === 3, { timeout: 30000, polling: 100 });
  const before = await page.evaluate(snapshot);
  await page.waitForFunction(() => document.body.dataset.finished === 'true', { timeout: 60000, polling: 100 });
  const s = await page.evaluate(snapshot);
  check(JSON.stringify(s.lanes) === '["Drone1","Drone2","Drone3"]', 'three lanes, Drone1 to Drone3: ' + s.lanes);
  check(s.outcome === 'completed', 'the page saw the launched mission complete: ' + s.outcome);
  check(s.events > before.events, `events came live (${before.events} when the lanes appeared, ${s.events} at the end)`);
  const d3 = s.bars.filter(b => b.drone === 'Drone3').map(b => b.name + ':' + b.outcome).join(' ');
  check(d3 === 'Arm:succeeded Takeoff:succeeded Sensor2:succeeded FlyByX:succeeded Land:succeeded Disarm:succeeded',
        'Drone3 flew its part to the end: ' + d3);
  check(s.triggers.some(t => t.from === 'Drone1' && t.to === 'Drone3'), 'the Drone1 → Drone3 trigger crossed between processes');
  check(Object.keys(s.nodes).length > 20, 'the graph comes from the manifest\'s source: ' + Object.keys(s.nodes).length + ' nodes');
  await page.screenshot({ path: path.join(shots, 'launch-listing2-end.png'), fullPage: true });
}

// A live run whose action fails (tests/monitor/missions/timeout.eamos): the banner with drone,
// action, line and reason; "● live" gone once the outcome is in; the failed drone marked; each
// bar's outcome and reason on a click; next / previous failure past either end.
async function failedLive(browser) {
  const page = await open(browser, '');
  await page.waitForFunction(() => document.querySelectorAll('.lane').length === 2, { timeout: 30000, polling: 50 });
  const first = await page.evaluate(snapshot);
  if (first.outcome === '') check(first.mode === 'live', 'before its outcome the run is live: ' + first.mode);
  await page.waitForFunction(() => document.getElementById('outcome').dataset.outcome === 'failed',
                             { timeout: 30000, polling: 50 });
  const atEnd = await page.evaluate(() => ({ mode: document.getElementById('mode').dataset.mode,
    text: document.getElementById('mode').textContent, finished: document.body.dataset.finished === 'true' }));
  check(atEnd.mode === 'ended' && !atEnd.text.includes('live ●') && atEnd.text !== '● live',
        `once the run failed the page no longer says live: "${atEnd.text}"` +
        (atEnd.finished ? '' : ' (while the drones still land)'));
  const banner = await page.evaluate(() => { const b = document.getElementById('banner');
    return { hidden: b.hidden, text: document.getElementById('banner-text').textContent, ...b.dataset }; });
  check(!banner.hidden && banner.drone === 'Drone2' && banner.action === 'FlyByX' && banner.line === '11' &&
        banner.reason === 'timed out after 2.0 s', 'the banner: ' + banner.text);
  check(banner.text.startsWith('Mission failed at 3.65 s: Drone2 · Drone2.FlyByX(40) · line 11 · timed out after 2.0 s'),
        'it reads: ' + banner.text);
  await page.waitForFunction(() => document.body.dataset.finished === 'true', { timeout: 60000, polling: 100 });
  await page.evaluate(() => window.eamosMonitor.setClock(1e9));
  const marks = await page.evaluate(() => ({
    lanes: [...document.querySelectorAll('.lane.failed')].map(l => l.dataset.drone),
    fail: [...document.querySelectorAll('.fail-mark')].map(m => m.dataset.drone + ':' + m.dataset.reason),
    list: [...document.querySelectorAll('#drone-list li.failed')].map(li => li.dataset.drone),
    map: window.eamosMonitor.failedDrones(), mode: document.getElementById('mode').dataset.mode }));
  check(JSON.stringify(marks.lanes) === '["Drone2"]' && JSON.stringify(marks.fail) === '["Drone2:timed out after 2.0 s"]',
        'Drone2\'s lane is marked failed, with a ✗ at the failure: ' + JSON.stringify(marks));
  check(JSON.stringify(marks.list) === '["Drone2"]' && JSON.stringify(marks.map) === '["Drone2"]',
        'and so are its line under the map and its place on the map');
  check(marks.mode === 'ended', 'after the end the page says the live run ended: ' + marks.mode);
  const clickBar = async (drone, name) => {
    await page.click(`.bar[data-drone="${drone}"][data-name="${name}"]`);
    return page.evaluate(() => ({ ...document.getElementById('selection').dataset,
                                  text: document.getElementById('selection').textContent }));
  };
  let sel = await clickBar('Drone2', 'FlyByX');
  check(sel.outcome === 'failed' && sel.reason === 'timed out after 2.0 s' && sel.text.includes('1.65 s to 3.65 s'),
        'a click on the red bar: ' + sel.text);
  sel = await clickBar('Drone1', 'FlyByX');
  check(sel.outcome === 'cancelled' && sel.reason === 'cancelled', 'on Drone1\'s FlyByX: ' + sel.text);
  sel = await clickBar('Drone1', 'Takeoff');
  check(sel.outcome === 'succeeded' && sel.reason === '', 'on a green bar: ' + sel.text);
  const jump = async (button, from) => {
    await page.evaluate(t => window.eamosMonitor.setClock(t), from);
    await page.click(button);
    return page.evaluate(() => ({ t: Number(document.getElementById('clock').dataset.t),
      text: document.getElementById('selection').textContent, ...document.getElementById('selection').dataset }));
  };
  let j = await jump('#next-failure', 0);
  check(Math.abs(j.t - 3.65) < 1e-6 && j.text.startsWith('failure 1 of 1:') && j.outcome === 'failed' &&
        j.reason === 'timed out after 2.0 s', 'next failure from 0 s: ' + j.text);
  j = await jump('#next-failure', 5);
  check(Math.abs(j.t - 3.65) < 1e-6 && j.text.includes('back to the first'), 'next failure after the last: ' + j.text);
  j = await jump('#prev-failure', 0);
  check(Math.abs(j.t - 3.65) < 1e-6 && j.text.includes('back to the last'), 'previous failure before the first: ' + j.text);
  j = await jump('#prev-failure', 8);
  check(Math.abs(j.t - 3.65) < 1e-6 && j.text.startsWith('failure 1 of 1:'), 'previous failure from the end: ' + j.text);
  await page.evaluate(() => window.eamosMonitor.setClock(5));
  await page.screenshot({ path: path.join(shots, 'live-failed-run.png'), fullPage: true });
}

// Four drones at the end of each PAR wait for the slowest: one span per pause, and the labels
// neither overlap nor overflow their spans (tests/monitor/missions/par4.eamos).
// `eamos run --trace` of tests/launch/missions/separation_crossing.eamos: B gives way to A
// and flies on; its lane holds an orange ⏸ and ▶ naming A and their distance, A's lane none,
// and while B holds the map says so.
async function giveWay(browser) {
  const page = await open(browser, '?t=0');
  await page.waitForSelector('body[data-finished="true"]', { timeout: 15000, polling: 100 });
  const marks = await page.evaluate(() => [...document.querySelectorAll('.give-way')].map(m => ({
    lane: m.closest('.lane') ? m.closest('.lane').dataset.drone : '', event: m.dataset.event, other: m.dataset.other,
    t: Number(m.dataset.t), title: m.title, text: m.textContent, colour: getComputedStyle(m).backgroundColor })));
  const events = marks.map(m => m.lane + ':' + m.event + ':' + m.text).join(' ');
  check(events === 'B:give_way:⏸ B:resume:▶', 'B\'s lane has its give-way and its resume, A\'s none: ' + events);
  const g = marks[0] || {};
  check(g.other === 'A' && (g.title || '').includes('give way A') && (g.title || '').includes('m apart'),
        'the give-way names A and the distance: ' + g.title);
  check(g.colour === 'rgb(255, 140, 0)', 'the mark is orange: ' + g.colour);
  await page.screenshot({ path: path.join(shots, 'replay-give-way.png'), fullPage: true });
}

async function waits(browser) {
  const page = await open(browser, '?t=9.2');
  await page.waitForSelector('body[data-finished="true"]', { timeout: 15000, polling: 100 });
  const r = await page.evaluate(() => [...document.querySelectorAll('.lane')].map(lane => ({
    drone: lane.dataset.drone,
    spans: [...lane.querySelectorAll('.wait')].map(w => { const b = w.getBoundingClientRect();
      return { left: b.left, right: b.right, text: w.textContent, on: w.dataset.on, fits: w.scrollWidth <= w.clientWidth + 1 }; }) })));
  let labels = 0;
  for (const lane of r) {
    const spans = lane.spans.sort((a, b) => a.left - b.left);
    labels += spans.filter(s => s.text).length;
    const overlap = spans.some((s, i) => i > 0 && s.left < spans[i - 1].right - 0.5);
    check(!overlap, `${lane.drone}: ${spans.length} wait spans, none over another`);
    check(spans.every(s => s.fits), `${lane.drone}: every label fits its span (${spans.map(s => s.text || '·').join(' | ')})`);
  }
  check(labels >= 4, `${labels} spans are labelled`);
  const d1 = r.find(l => l.drone === 'D1');
  check(d1 && d1.spans.length >= 2 && d1.spans.every(s => s.on === 'D4'), 'D1 waits on D4, the slowest, each time: ' +
        JSON.stringify(d1 && d1.spans.map(s => s.on)));
  await page.screenshot({ path: path.join(shots, 'replay-par4-waits.png'), fullPage: true });
}

(async () => {
  fs.mkdirSync(shots, { recursive: true });
  const { browser, profile } = await launch();
  try {
    if (mode === 'replay') await replay(browser);
    else if (mode === 'live') await live(browser);
    else if (mode === 'live20') await live20(browser);
    else if (mode === 'live1000') await liveScale(browser, 1000, 100, 8000);
    else if (mode === 'launch') await launchLive(browser);
    else if (mode === 'v1') await v1(browser);
    else if (mode === 'scale') await scale(browser);
    else if (mode === 'palette') await palette(browser);
    else if (mode === 'violation') await violation(browser);
    else if (mode === 'failed') await failedLive(browser);
    else if (mode === 'waits') await waits(browser);
    else if (mode === 'giveway') await giveWay(browser);
    else failures.push('unknown mode ' + mode);
  } finally {
    await browser.close();
    fs.rmSync(profile, { recursive: true, force: true });
  }
  if (failures.length) { for (const f of failures) console.log('FAIL: ' + f); process.exit(1); }
  console.log('all checks passed');
})().catch(e => { console.log('FAIL: ' + (e && e.stack || e)); process.exit(1); });
