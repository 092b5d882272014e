// The viewer's page: plays a run back from the `crowddb view` server. The server sends the run's
// static parts once (/api/run), per-tick metrics (/api/metrics) and frames in windows
// (/api/frames, a binary layout: see src/view/server.cpp); the page keeps a few windows around
// the playhead and fetches the next one ahead of it, so the whole file is never loaded at once.
import uPlot from 'uplot';
import 'uplot/dist/uPlot.min.css';
import './style.css';

const SHADES = ['active', 'frozen', 'arrived', 'unknown', 'stalled', 'waiting'];  // codes of the frame layout
const COLOURS = { active: '#1f77b4', frozen: '#ff7f0e', arrived: '#9e9e9e', unknown: '#1f77b4', stalled: '#9467bd', waiting: '#17becf' };
const FLOOR = '#f3efe6', BLOCKED = '#4d4d4d';
const VIRIDIS = [[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]];
const MAX_WINDOWS = 6;

const $ = (id) => document.getElementById(id);
const canvas = $('scene');
const ctx = canvas.getContext('2d');

const st = {
  run: null,
  window: 1,             // frames per window
  windows: new Map(),    // window start -> array of frames
  loading: new Map(),    // window start -> promise
  frame: 0,              // the frame on show
  shown: null,           // its data, once loaded
  time: 0,               // [s] playhead, from the first frame
  playing: false,
  speed: 1,
  colour: 'state',
  density: false,
  view: { cx: 0, cy: 0, s: 1 },
  hover: null, // the hovered agent's index in the frame on show, and its id
  hoverId: null,
  chart: null,
  lastChart: 0,
};

// --- data ---------------------------------------------------------------------------------

function parseWindow(buf) {
  const dv = new DataView(buf);
  if (dv.getUint32(0, true) !== 0x46424443) throw new Error('not a frame window');
  const count = dv.getUint32(4, true);
  const frames = [];
  let at = 8;
  for (let f = 0; f < count; ++f) {
    const frame = dv.getInt32(at, true), n = dv.getUint32(at + 4, true);
    const start = at + 8;
    const id = new Float64Array(buf, start, n);
    const x = new Float32Array(buf, start + 8 * n, n);
    const y = new Float32Array(buf, start + 12 * n, n);
    const r = new Float32Array(buf, start + 16 * n, n);
    const v = new Float32Array(buf, start + 20 * n, n);
    const goal = new Int32Array(buf, start + 24 * n, n);
    const shade = new Uint8Array(buf, start + 28 * n, n);
    frames.push({ frame, n, id, x, y, r, v, goal, shade });
    at = start + Math.ceil((29 * n) / 8) * 8;
  }
  return frames;
}

function windowStart(k) {
  const first = st.run.first_frame;
  return first + Math.floor((k - first) / st.window) * st.window;
}

function requestWindow(start) {
  if (st.windows.has(start) || st.loading.has(start)) return;
  if (start > st.run.last_frame || start < st.run.first_frame) return;
  const p = fetch(`api/frames?from=${start}&count=${st.window}`)
    .then((r) => {
      if (!r.ok) throw new Error(`frames ${start}: HTTP ${r.status}`);
      return r.arrayBuffer();
    })
    .then((buf) => {
      st.windows.set(start, parseWindow(buf));
      st.loading.delete(start);
      // Keep the windows nearest the playhead.
      if (st.windows.size > MAX_WINDOWS) {
        const keys = [...st.windows.keys()].sort((a, b) => Math.abs(b - st.frame) - Math.abs(a - st.frame));
        st.windows.delete(keys[0]);
      }
      // The frame on show may have been waiting for this window.
      if (!st.shown || st.shown.frame !== st.frame) showFrame(st.frame);
      draw();
    })
    .catch((e) => {
      st.loading.delete(start);
      status(String(e));
    });
  st.loading.set(start, p);
}

function frameData(k) {
  const w = windowStart(k);
  const frames = st.windows.get(w);
  if (!frames) {
    requestWindow(w);
    return null;
  }
  if (k - w > st.window / 2) requestWindow(w + st.window);  // read ahead
  return frames[k - w] && frames[k - w].frame === k ? frames[k - w] : frames.find((f) => f.frame === k) || null;
}

function showFrame(k) {
  k = Math.max(st.run.first_frame, Math.min(st.run.last_frame, k));
  const data = frameData(k);
  st.frame = k;
  $('scrub').value = String(k);
  if (data) st.shown = data;
  updateClock();
  return !!data;
}

// --- drawing ------------------------------------------------------------------------------

function resize() {
  const dpr = window.devicePixelRatio || 1;
  const w = canvas.clientWidth, h = canvas.clientHeight;
  canvas.width = Math.round(w * dpr);
  canvas.height = Math.round(h * dpr);
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
}

function fit() {
  const b = st.run.bounds;
  const w = canvas.clientWidth, h = canvas.clientHeight;
  st.view.s = 0.95 * Math.min(w / (b[2] - b[0]), h / (b[3] - b[1]));
  st.view.cx = (b[0] + b[2]) / 2;
  st.view.cy = (b[1] + b[3]) / 2;
}

const toScreen = (x, y) => [
  canvas.clientWidth / 2 + (x - st.view.cx) * st.view.s,
  canvas.clientHeight / 2 - (y - st.view.cy) * st.view.s,
];
const toWorld = (px, py) => [
  st.view.cx + (px - canvas.clientWidth / 2) / st.view.s,
  st.view.cy - (py - canvas.clientHeight / 2) / st.view.s,
];

function polygon(ring) {
  ctx.beginPath();
  ring.forEach(([x, y], i) => {
    const [px, py] = toScreen(x, y);
    if (i) ctx.lineTo(px, py);
    else ctx.moveTo(px, py);
  });
  ctx.closePath();
}

function speedColour(f) {
  f = Number.isFinite(f) ? Math.max(0, Math.min(1, f)) * 4 : 0;
  const i = Math.min(3, Math.floor(f)), t = f - i;
  const c = VIRIDIS[i].map((a, j) => Math.round(a + t * (VIRIDIS[i + 1][j] - a)));
  return `rgb(${c[0]},${c[1]},${c[2]})`;
}

function topSpeed(d) {
  let top = 0.1;
  for (let i = 0; i < d.n; ++i) if (Number.isFinite(d.v[i])) top = Math.max(top, d.v[i]);
  return top;
}

function draw() {
  if (!st.run) return;
  const w = canvas.clientWidth, h = canvas.clientHeight, run = st.run, b = run.bounds;
  ctx.fillStyle = '#fff';
  ctx.fillRect(0, 0, w, h);
  const [x0, y0] = toScreen(b[0], b[3]);
  ctx.fillStyle = FLOOR;
  ctx.fillRect(x0, y0, (b[2] - b[0]) * st.view.s, (b[3] - b[1]) * st.view.s);
  ctx.fillStyle = BLOCKED;
  for (const ring of run.blocked) {
    polygon(ring);
    ctx.fill();
  }
  ctx.strokeStyle = BLOCKED;
  ctx.lineWidth = 1;
  ctx.strokeRect(x0, y0, (b[2] - b[0]) * st.view.s, (b[3] - b[1]) * st.view.s);
  ctx.font = '11px sans-serif';
  ctx.textAlign = 'center';
  ctx.textBaseline = 'middle';
  for (const g of run.goals) {
    if (g.ring) polygon(g.ring);
    else {
      const [px, py] = toScreen(g.x, g.y);
      ctx.beginPath();
      ctx.arc(px, py, Math.max(2, g.radius * st.view.s), 0, 2 * Math.PI);
    }
    ctx.fillStyle = 'rgba(46,160,67,0.30)';
    ctx.fill();
    ctx.strokeStyle = 'rgba(46,128,56,0.9)';
    ctx.stroke();
    const c = g.ring ? g.ring.reduce((a, p) => [a[0] + p[0] / g.ring.length, a[1] + p[1] / g.ring.length], [0, 0]) : [g.x, g.y];
    const [px, py] = toScreen(c[0], c[1]);
    ctx.fillStyle = '#1a5a26';
    ctx.fillText(g.name, px, py);
  }
  const d = st.shown;
  if (d) {
    if (st.density) drawDensity(d);
    const top = topSpeed(d);
    const colourOf = (i) => (st.colour === 'speed' ? speedColour(d.v[i] / top) : COLOURS[SHADES[d.shade[i]] || 'unknown']);
    // Level of detail: discs when they are big enough to see (radius 1.5 px and more), else
    // squares written into an image of their own (10^5 agents in about 10 ms).
    if (d.n > 0 && d.r[0] * st.view.s >= 1.5) {
      let fill = '';
      for (let i = 0; i < d.n; ++i) {
        const [px, py] = toScreen(d.x[i], d.y[i]);
        if (px < -50 || py < -50 || px > w + 50 || py > h + 50) continue;
        const c = colourOf(i);
        if (c !== fill) ctx.fillStyle = fill = c;
        const rp = Math.max(d.r[i] * st.view.s, 1);
        ctx.beginPath();
        ctx.arc(px, py, rp, 0, 2 * Math.PI);
        ctx.fill();
        if (rp >= 3) {
          ctx.strokeStyle = 'rgba(0,0,0,0.45)';
          ctx.lineWidth = 0.75;
          ctx.stroke();
        }
      }
    } else {
      drawSquares(d, colourOf);
    }
    if (st.hover !== null && st.hover < d.n && d.id[st.hover] === st.hoverId) {
      const [px, py] = toScreen(d.x[st.hover], d.y[st.hover]);
      ctx.beginPath();
      ctx.arc(px, py, Math.max(d.r[st.hover] * st.view.s, 3) + 2, 0, 2 * Math.PI);
      ctx.strokeStyle = '#d62728';
      ctx.lineWidth = 2;
      ctx.stroke();
    }
  }
  legend();
}

// Agents as squares of pixels (side 2 r, at least 1 px), written into an image of their own
// (transparent elsewhere) that is then laid over the scene: no read-back of the canvas.
const layer = { canvas: document.createElement('canvas'), img: null };
function drawSquares(d, colourOf) {
  const dpr = window.devicePixelRatio || 1;
  const W = canvas.width, H = canvas.height;
  if (!layer.img || layer.img.width !== W || layer.img.height !== H) {
    layer.canvas.width = W;
    layer.canvas.height = H;
    layer.img = new ImageData(W, H);
  }
  const px32 = new Uint32Array(layer.img.data.buffer);
  px32.fill(0);
  const rgba = new Map();
  const pack = (css) => {
    let v = rgba.get(css);
    if (v === undefined) {
      const m = css.startsWith('#')
        ? [1, 3, 5].map((k) => parseInt(css.slice(k, k + 2), 16))
        : css.match(/\d+/g).map(Number);
      v = ((255 << 24) | (m[2] << 16) | (m[1] << 8) | m[0]) >>> 0;  // little-endian RGBA
      rgba.set(css, v);
    }
    return v;
  };
  const s = st.view.s * dpr, ox = canvas.clientWidth / 2 * dpr, oy = canvas.clientHeight / 2 * dpr;
  for (let i = 0; i < d.n; ++i) {
    const sx = ox + (d.x[i] - st.view.cx) * s, sy = oy - (d.y[i] - st.view.cy) * s;
    const half = Math.max(0.5, d.r[i] * s);
    const x0 = Math.max(0, Math.round(sx - half)), x1 = Math.min(W, Math.max(x0 + 1, Math.round(sx + half)));
    const y0 = Math.max(0, Math.round(sy - half)), y1 = Math.min(H, Math.max(y0 + 1, Math.round(sy + half)));
    if (x0 >= W || y0 >= H || x1 <= 0 || y1 <= 0) continue;
    const c = pack(colourOf(i));
    for (let y = y0; y < y1; ++y) px32.fill(c, y * W + x0, y * W + x1);
  }
  layer.canvas.getContext('2d').putImageData(layer.img, 0, 0);
  ctx.save();
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.drawImage(layer.canvas, 0, 0);
  ctx.restore();
}

function drawDensity(d) {
  const b = st.run.bounds, cells = new Map();
  for (let i = 0; i < d.n; ++i) {
    const key = `${Math.floor(d.x[i] - b[0])},${Math.floor(d.y[i] - b[1])}`;
    cells.set(key, (cells.get(key) || 0) + 1);
  }
  for (const [key, count] of cells) {
    const [ix, iy] = key.split(',').map(Number);
    const cx = ix + b[0], cy = iy + b[1];
    const [px, py] = toScreen(cx, cy + 1);
    // People per m^2 in 1 m cells; full red at 4 /m^2 and above.
    ctx.fillStyle = `rgba(214,39,40,${Math.min(1, count / 4) * 0.6})`;
    ctx.fillRect(px, py, st.view.s, st.view.s);
  }
}

function legend() {
  const d = st.shown;
  if (!d) return;
  let html = '';
  if (st.colour === 'speed') {
    const top = topSpeed(d);
    for (let s = 0; s <= 4; ++s)
      html += `<span class="key" style="background:${speedColour(s / 4)}"></span>${(top * s / 4).toFixed(2)}`;
    html += ' m/s';
  } else {
    const count = [0, 0, 0, 0, 0, 0];
    for (let i = 0; i < d.n; ++i) ++count[d.shade[i]];
    if (st.run.crowddb)
      html += `<span class="key" style="background:${COLOURS.active}"></span>active ${count[0] + count[3]}` +
        `<span class="key" style="background:${COLOURS.stalled}"></span>stalled ${count[4]}` +
        `<span class="key" style="background:${COLOURS.frozen}"></span>frozen ${count[1]}` +
        `<span class="key" style="background:${COLOURS.arrived}"></span>arrived ${count[2]}` +
        (count[5] > 0 ? `<span class="key" style="background:${COLOURS.waiting}"></span>waiting ${count[5]}` : '');
    else html += `<span class="key" style="background:${COLOURS.unknown}"></span>${d.n} agents (radius 0.2 m: not in the file)`;
  }
  if (st.density) html += '<span class="key" style="background:rgba(214,39,40,0.6)"></span>4+ people/m²';
  $('legend').innerHTML = html;
}

// --- playback -----------------------------------------------------------------------------

const fps = () => (st.run.fps > 0 ? st.run.fps : 10);

function updateClock() {
  const t = st.frame / fps();
  $('clock').textContent = `${t.toFixed(1)} s  (frame ${st.frame})`;
  const now = performance.now();
  if (st.chart && now - st.lastChart > 250) {
    st.lastChart = now;
    st.chart.redraw(false, false);
  }
}

function status(text) {
  $('status').textContent = text;
}

let last = null;
function tick(ts) {
  if (st.playing && last !== null) {
    const k = Math.max(st.run.first_frame, Math.floor(st.time * fps()));
    if (frameData(k)) {  // hold the playhead while a window is on its way
      st.time += ((ts - last) / 1000) * st.speed;
      const next = Math.min(st.run.last_frame, Math.max(st.run.first_frame, Math.floor(st.time * fps())));
      if (next !== st.frame) {
        showFrame(next);
        draw();
      }
      if (next >= st.run.last_frame) setPlaying(false);
    }
  }
  last = ts;
  requestAnimationFrame(tick);
}

function setPlaying(on) {
  st.playing = on;
  if (on && st.frame >= st.run.last_frame) {
    st.time = st.run.first_frame / fps();
    showFrame(st.run.first_frame);
  }
  $('play').innerHTML = on ? '&#10074;&#10074;' : '&#9654;';
}

function seek(k) {
  k = Math.max(st.run.first_frame, Math.min(st.run.last_frame, k));
  st.time = k / fps();  // frame k is at time k / fps
  showFrame(k);
  draw();
}

// --- interaction --------------------------------------------------------------------------

function hoverAt(mx, my) {
  const d = st.shown;
  st.hover = null;
  const tip = $('tip');
  if (!d) return;
  const [wx, wy] = toWorld(mx, my);
  let best = Infinity;
  const slack = 3 / st.view.s;  // 3 px around small discs
  for (let i = 0; i < d.n; ++i) {
    const dx = d.x[i] - wx, dy = d.y[i] - wy, d2 = dx * dx + dy * dy;
    const reach = d.r[i] + slack;
    if (d2 <= reach * reach && d2 < best) {
      best = d2;
      st.hover = i;
    }
  }
  st.hoverId = st.hover === null ? null : d.id[st.hover];
  if (st.hover === null) {
    tip.hidden = true;
  } else {
    const i = st.hover, g = d.goal[i] >= 0 && st.run.goals[d.goal[i]] ? st.run.goals[d.goal[i]].name : '-';
    tip.textContent = `agent ${d.id[i]}\ngoal ${g}\nspeed ${d.v[i].toFixed(2)} m/s\nstate ${SHADES[d.shade[i]]}` +
      `\nat ${d.x[i].toFixed(2)}, ${d.y[i].toFixed(2)} m`;
    tip.hidden = false;
    tip.style.left = `${mx + 14}px`;
    tip.style.top = `${my + 14}px`;
  }
  draw();
}

function wire() {
  const scrub = $('scrub');
  scrub.min = String(st.run.first_frame);
  scrub.max = String(st.run.last_frame);
  scrub.addEventListener('input', () => {
    setPlaying(false);
    seek(Number(scrub.value));
  });
  $('play').addEventListener('click', () => setPlaying(!st.playing));
  $('speed').addEventListener('change', (e) => (st.speed = Number(e.target.value)));
  $('colour').addEventListener('change', (e) => {
    st.colour = e.target.value;
    draw();
  });
  $('density').addEventListener('change', (e) => {
    st.density = e.target.checked;
    draw();
  });
  $('fit').addEventListener('click', () => {
    fit();
    draw();
  });
  canvas.addEventListener('dblclick', () => {
    fit();
    draw();
  });
  canvas.addEventListener('wheel', (e) => {
    e.preventDefault();
    const r = canvas.getBoundingClientRect(), mx = e.clientX - r.left, my = e.clientY - r.top;
    const [wx, wy] = toWorld(mx, my);
    st.view.s *= Math.exp(-e.deltaY * 0.0015);
    const [nx, ny] = toWorld(mx, my);  // keep the point under the cursor in place
    st.view.cx += wx - nx;
    st.view.cy += wy - ny;
    draw();
  }, { passive: false });
  let drag = null;
  canvas.addEventListener('mousedown', (e) => {
    drag = { x: e.clientX, y: e.clientY, cx: st.view.cx, cy: st.view.cy };
    canvas.classList.add('dragging');
  });
  window.addEventListener('mouseup', () => {
    drag = null;
    canvas.classList.remove('dragging');
  });
  canvas.addEventListener('mousemove', (e) => {
    const r = canvas.getBoundingClientRect();
    if (drag) {
      st.view.cx = drag.cx - (e.clientX - drag.x) / st.view.s;
      st.view.cy = drag.cy + (e.clientY - drag.y) / st.view.s;
      draw();
      return;
    }
    hoverAt(e.clientX - r.left, e.clientY - r.top);
  });
  canvas.addEventListener('mouseleave', () => {
    st.hover = null;
    st.hoverId = null;
    $('tip').hidden = true;
    draw();
  });
  window.addEventListener('keydown', (e) => {
    if (e.target.tagName === 'INPUT' && e.target.type !== 'checkbox') return;
    if (e.code === 'Space') {
      e.preventDefault();
      setPlaying(!st.playing);
    } else if (e.code === 'ArrowRight') seek(st.frame + 1);
    else if (e.code === 'ArrowLeft') seek(st.frame - 1);
  });
  window.addEventListener('resize', () => {
    resize();
    draw();
    if (st.chart) st.chart.setSize({ width: $('chart').clientWidth, height: 180 });
  });
}

// --- the metrics chart --------------------------------------------------------------------

function chart(m) {
  if (!m || !m.time.length) {
    $('chart').textContent = st.run.crowddb ? 'no per-tick metrics in this file' : '';
    return;
  }
  let total = 0;
  const arrived = m.arrived.map((a) => (total += a));
  const cursor = {
    hooks: {
      draw: [(u) => {
        const t = st.frame / fps();  // frame k holds tick k x every: time k / fps
        const x = u.valToPos(t, 'x', true);
        const c = u.ctx;
        c.save();
        c.strokeStyle = '#d62728';
        c.lineWidth = 2;
        c.beginPath();
        c.moveTo(x, u.bbox.top);
        c.lineTo(x, u.bbox.top + u.bbox.height);
        c.stroke();
        c.restore();
      }],
    },
  };
  st.chart = new uPlot({
    width: $('chart').clientWidth,
    height: 180,
    plugins: [cursor],
    scales: { x: { time: false } },
    axes: [{ label: 's' }, { label: 'agents' }, { side: 1, label: 'ms per tick', scale: 'ms', grid: { show: false } }],
    series: [
      {},
      { label: 'arrived (total)', stroke: '#2ca02c' },
      { label: 'frozen', stroke: '#ff7f0e' },
      { label: 'stalled', stroke: '#9467bd' },
      { label: 'overlaps', stroke: '#d62728' },
      { label: 'ms/tick', stroke: '#7f7f7f', scale: 'ms' },
    ],
  }, [m.time, arrived, m.frozen, m.stalled, m.overlaps, m.ms], $('chart'));
}

// --- start --------------------------------------------------------------------------------

async function start() {
  const t0 = performance.now();
  const run = await (await fetch('api/run')).json();
  st.run = run;
  document.title = `${run.name} - crowddb view`;
  $('title').textContent = run.name;
  st.window = Math.max(1, Math.min(200, Math.floor(200000 / Math.max(1, run.max_agents))));
  resize();
  fit();
  wire();
  status(`${run.last_frame - run.first_frame + 1} frames at ${run.fps > 0 ? run.fps : '?'} fps, up to ${run.max_agents} agents`);
  showFrame(run.first_frame);
  await st.loading.get(windowStart(run.first_frame));
  draw();
  window.crowddbViewer.firstFrameMs = performance.now() - t0;
  window.crowddbViewer.ready = true;
  requestAnimationFrame(tick);
  fetch('api/metrics').then((r) => r.json()).then(chart).catch((e) => status(String(e)));
}

// The page's state, for tests and the curious (the browser test reads it).
window.crowddbViewer = {
  ready: false,
  firstFrameMs: null,
  get frame() { return st.frame; },
  get playing() { return st.playing; },
  loaded: () => !!st.shown && st.shown.frame === st.frame,
  seek: (k) => seek(k),
  play: (on) => setPlaying(on),
  toScreen: (x, y) => toScreen(x, y),
  agents: () => {
    const d = st.shown;
    if (!d) return [];
    const out = [];
    for (let i = 0; i < d.n; ++i) {
      const [px, py] = toScreen(d.x[i], d.y[i]);
      out.push({ id: d.id[i], x: d.x[i], y: d.y[i], r: d.r[i], px, py, shade: SHADES[d.shade[i]] });
    }
    return out;
  },
  hovered: () => st.hoverId,
  // Milliseconds per redraw of the current frame (the median of n), for the frame-rate figure.
  drawMs: (n = 20) => {
    const t = [];
    for (let i = 0; i < n; ++i) {
      const a = performance.now();
      draw();
      t.push(performance.now() - a);
    }
    t.sort((a, b) => a - b);
    return t[Math.floor(n / 2)];
  },
};

start().catch((e) => status(`could not load the run: ${e}`));
