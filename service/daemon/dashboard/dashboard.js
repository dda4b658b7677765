// facet station dashboard: polls the daemon's JSON endpoints and redraws in place.
// Read-only: the two changing actions ask for the station token each time and send it as a
// Bearer header; the token is never stored in the page.
'use strict';

const POLL_MS = 1000;
const state = { lastPartId: null, polls: 0, firstRenderMs: null, errors: 0 };
window.facetDashboard = state;  // lets tests and operators see what the page has seen

const $ = (id) => document.getElementById(id);

async function getJson(url) {
  const response = await fetch(url, { cache: 'no-store' });
  // /healthz answers 503 with a JSON body when the station is down: still worth showing.
  return { status: response.status, body: await response.json() };
}

function badge(el, label, cls) {
  el.textContent = label;
  el.className = 'badge ' + cls;
}

function renderHealth(h) {
  badge($('health-status'), h.status || 'unknown',
        h.status === 'ok' ? 'ok' : h.status === 'degraded' ? 'warn' : 'bad');
  const cam = h.camera || {};
  badge($('health-camera'), 'camera ' + (cam.connected ? 'connected' : 'lost') +
        (cam.frames !== undefined ? ' · ' + cam.frames + ' frames' : ''),
        cam.connected ? 'ok' : 'bad');
  const plc = h.plc || {};
  if (plc.configured === false) badge($('health-plc'), 'PLC off', 'off');
  else badge($('health-plc'), 'PLC ' + (plc.connected ? 'connected' : 'disconnected'),
             plc.connected ? 'ok' : 'bad');
  const recipe = h.recipe || {};
  const problems = (recipe.problems || []).length;
  badge($('health-recipe'), 'recipe ' + (recipe.id ?? '?') +
        (problems ? ' · ' + problems + ' problem(s)' : ''), problems ? 'warn' : 'ok');
  $('health-recipe').title = (recipe.problems || []).join('\n');
  // On the page, not only in the badge's tooltip: a rejected recipe needs someone to act.
  const list = (recipe.problems || []).map((text) => {
    const item = document.createElement('li');
    item.textContent = text;
    return item;
  });
  $('recipe-problem-list').replaceChildren(...list);
  $('recipe-problems').hidden = list.length === 0;
}

function renderCounts(counts) {
  const pass = counts.pass || 0, fail = counts.fail || 0, error = counts.error || 0;
  const total = pass + fail + error;
  $('count-pass').textContent = pass;
  $('count-fail').textContent = fail;
  $('count-error').textContent = error;
  $('count-total').textContent = total;
  $('yield').textContent = total ? 'yield ' + (100 * pass / total).toFixed(1) + ' %' : 'yield –';
}

function renderStrip(parts) {
  const strip = $('strip');
  const cells = [];
  for (let i = 0; i < 50; ++i) {
    const part = parts[parts.length - 50 + i];
    const cell = document.createElement('div');
    cell.className = 'cell' + (part ? ' ' + part.verdict : '');
    if (part) cell.title = 'part ' + part.part_id + (part.serial ? ' ' + part.serial : '') +
                           ': ' + part.verdict;
    cells.push(cell);
  }
  strip.replaceChildren(...cells);
}

function renderLast(parts) {
  const last = parts[parts.length - 1];
  if (!last) return;
  $('last-part').textContent = '#' + last.part_id + (last.serial ? ' · ' + last.serial : '') +
                               ' · ' + last.verdict + ' · ' + last.inspection_ms.toFixed(1) + ' ms';
  const failed = last.error ? last.error : (last.failed_checks || []).join(', ');
  $('last-failed').textContent = failed ? 'failed: ' + failed : '';
  // Reservations about results that stand (a tool partly outside the image).
  $('last-notes').textContent = (last.notes || []).join(' · ');
  if (last.part_id !== state.lastPartId) {
    state.lastPartId = last.part_id;
    $('last-image').src = '/api/last.png?part=' + last.part_id;
  }
}

// One canvas per check: measured values of the recent parts over their tolerance band.
function drawTrend(canvas, check, parts) {
  const dpr = window.devicePixelRatio || 1;
  const w = canvas.clientWidth, h = canvas.clientHeight;
  canvas.width = Math.round(w * dpr);
  canvas.height = Math.round(h * dpr);
  const g = canvas.getContext('2d');
  g.scale(dpr, dpr);
  g.clearRect(0, 0, w, h);
  const points = [];
  parts.forEach((p, i) => {
    const v = p.values && p.values[check.name];
    if (v && typeof v.value === 'number') points.push({ i, value: v.value, pass: v.pass });
  });
  let lo = Math.min(check.lower, check.nominal), hi = Math.max(check.upper, check.nominal);
  for (const p of points) { lo = Math.min(lo, p.value); hi = Math.max(hi, p.value); }
  if (!(hi > lo)) { hi = lo + 1; lo -= 1; }
  const margin = 0.12 * (hi - lo);
  lo -= margin; hi += margin;
  const left = 8, right = w - 64, top = 8, bottom = h - 16;
  const x = (i) => left + (right - left) * (parts.length > 1 ? i / (parts.length - 1) : 0.5);
  const y = (v) => bottom - (bottom - top) * (v - lo) / (hi - lo);
  // Tolerance band and nominal.
  g.fillStyle = 'rgba(52, 179, 86, 0.22)';
  g.fillRect(left, y(check.upper), right - left, y(check.lower) - y(check.upper));
  g.strokeStyle = '#34b356';
  g.lineWidth = 1;
  for (const limit of [check.lower, check.upper]) {
    g.beginPath(); g.moveTo(left, y(limit)); g.lineTo(right, y(limit)); g.stroke();
  }
  g.setLineDash([4, 4]);
  g.strokeStyle = '#9aa5b1';
  g.beginPath(); g.moveTo(left, y(check.nominal)); g.lineTo(right, y(check.nominal)); g.stroke();
  g.setLineDash([]);
  g.fillStyle = '#aab4c0';
  g.font = '11px system-ui, sans-serif';
  g.fillText(fmt(check.upper), right + 4, y(check.upper) + 4);
  g.fillText(fmt(check.lower), right + 4, y(check.lower) + 4);
  if (!points.length) {
    g.fillText('no values yet', left + 4, top + 12);
    return;
  }
  // Measured values: a line, then the points, red outside the band.
  g.strokeStyle = '#7fb3ff';
  g.lineWidth = 1.5;
  g.beginPath();
  points.forEach((p, k) => (k ? g.lineTo(x(p.i), y(p.value)) : g.moveTo(x(p.i), y(p.value))));
  g.stroke();
  for (const p of points) {
    g.fillStyle = p.pass ? '#7fb3ff' : '#ff5b4f';
    g.beginPath(); g.arc(x(p.i), y(p.value), 3, 0, 2 * Math.PI); g.fill();
  }
  const last = points[points.length - 1];
  g.fillStyle = last.pass ? '#e8eaed' : '#ff5b4f';
  g.fillText(fmt(last.value), right + 4, Math.min(bottom, Math.max(top + 10, y(last.value) + 4)));
}

function fmt(v) {
  return Math.abs(v) >= 100 ? v.toFixed(1) : Math.abs(v) >= 1 ? v.toFixed(3) : v.toPrecision(3);
}

function renderCharts(checks, parts) {
  const box = $('charts');
  const key = checks.map((c) => c.name).join('|');
  if (box.dataset.key !== key) {
    box.dataset.key = key;
    box.replaceChildren();
    for (const check of checks) {
      const div = document.createElement('div');
      div.className = 'chart';
      const title = document.createElement('h3');
      title.textContent = check.name + (check.unit ? ' [' + check.unit + ']' : '') + '  ' +
                          fmt(check.lower) + ' … ' + fmt(check.upper);
      const canvas = document.createElement('canvas');
      canvas.dataset.check = check.name;
      div.append(title, canvas);
      box.append(div);
    }
    if (!checks.length) box.innerHTML = '<p class="empty">this recipe has no checks</p>';
  }
  const canvases = box.querySelectorAll('canvas');
  checks.forEach((check, k) => drawTrend(canvases[k], check, parts));
}

async function poll() {
  try {
    const [summary, health] = await Promise.all([getJson('/api/summary'), getJson('/healthz')]);
    const s = summary.body;
    $('station-recipe').textContent = s.recipe ? '· recipe ' + s.recipe.id + ' ' + s.recipe.name : '';
    renderHealth(health.body);
    renderCounts(s.counts || {});
    const parts = s.recent || [];
    renderStrip(parts);
    renderLast(parts);
    renderCharts(s.checks || [], parts);
    state.polls += 1;
    if (state.firstRenderMs === null) state.firstRenderMs = performance.now();
    $('updated').textContent = 'updated ' + new Date().toLocaleTimeString();
  } catch (e) {
    state.errors += 1;
    $('updated').textContent = 'station unreachable (' + e.message + ')';
  }
  setTimeout(poll, POLL_MS);
}

async function action(url, body) {
  const token = window.prompt('Station token (needed to change anything):');
  if (token === null) return;
  const response = await fetch(url, {
    method: 'POST',
    headers: { 'Authorization': 'Bearer ' + token, 'Content-Type': 'application/json' },
    body: JSON.stringify(body || {}),
  });
  const answer = await response.json().catch(() => ({}));
  $('action-message').textContent = response.ok ? (answer.message || 'done')
      : response.status === 403 ? 'refused: this station is read-only (no token configured)'
      : response.status === 401 ? 'refused: wrong token'
      : 'refused: ' + (answer.error || answer.message || response.status);
}

$('action-recipe').addEventListener('click', () => {
  const id = window.prompt('Recipe number to switch to:');
  if (id !== null && id.trim() !== '') action('/api/recipe', { id: Number(id) });
});
$('action-reset').addEventListener('click', () => action('/api/counters/reset'));
window.addEventListener('resize', () => { $('charts').dataset.key = ''; });
poll();
