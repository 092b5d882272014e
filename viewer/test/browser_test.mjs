// The viewer in a real browser: headless Chromium (Debian's, driven by playwright-core; nothing
// is downloaded) opens `crowddb view` on a run and checks, on the page's own canvas, that every
// agent of two frames is drawn where the file says it is (pixel probes at the file's positions),
// that the scrubber moves the playhead, that hovering an agent names it, and that playing
// advances; it saves a screenshot and prints the time to the first frame and the draw rate.
//
//   node test/browser_test.mjs --cli build/crowddb --run RUN.sqlite [--screenshot out.png]
//                              [--frames 0,300] [--measure-only] [--at FRAME]
import { spawn, execFileSync } from 'node:child_process';
import { chromium } from 'playwright-core';

const args = Object.fromEntries(
  process.argv.slice(2).reduce((acc, a, i, all) => (a.startsWith('--') ? [...acc, [a.slice(2), all[i + 1] && !all[i + 1].startsWith('--') ? all[i + 1] : 'true']] : acc), []),
);
const cli = args.cli, run = args.run;
if (!cli || !run) {
  console.error('usage: browser_test.mjs --cli CROWDDB --run RUN.sqlite [--screenshot FILE] [--frames A,B] [--measure-only]');
  process.exit(2);
}
const chromiumPath = process.env.CHROMIUM || '/usr/bin/chromium';
let failures = 0;
const check = (ok, what) => {
  if (!ok) ++failures;
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
};

// The file's own positions of frame k (the truth the page is checked against).
function truth(k) {
  const out = execFileSync('sqlite3', ['-readonly', run,
    `SELECT id, printf('%.9f', pos_x), printf('%.9f', pos_y) FROM trajectory_data WHERE frame = ${Number(k)} ORDER BY id`]);
  return out.toString().trim().split('\n').filter(Boolean).map((l) => {
    const [id, x, y] = l.split('|');
    return { id: Number(id), x: Number(x), y: Number(y) };
  });
}

const started = Date.now();
const server = spawn(cli, ['view', run, '--port', '0'], { stdio: ['ignore', 'pipe', 'pipe'] });
let stderr = '';
server.stderr.on('data', (d) => (stderr += d));
const url = await new Promise((resolve, reject) => {
  let out = '';
  server.stdout.on('data', (d) => {
    out += d;
    const m = out.match(/http:\/\/\S+/);
    if (m) resolve(m[0]);
  });
  server.on('exit', (code) => reject(new Error(`crowddb view exited with ${code}: ${stderr}`)));
  setTimeout(() => reject(new Error('crowddb view did not start within 60 s')), 60000).unref();
});

const serverMs = Date.now() - started;
const browser = await chromium.launch({
  executablePath: chromiumPath,
  headless: true,
  args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
    '--disable-component-update', '--disable-sync', '--disable-dev-shm-usage'],
});
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 900 }, deviceScaleFactor: 1 });
  const errors = [];
  page.on('pageerror', (e) => errors.push(String(e)));
  const t0 = Date.now();
  await page.goto(url);
  await page.waitForFunction(() => window.crowddbViewer && window.crowddbViewer.ready, null, { timeout: 120000 });
  const firstFrameMs = Date.now() - t0;
  const agents = await page.evaluate(() => window.crowddbViewer.agents().length);
  const drawMs = await page.evaluate(() => window.crowddbViewer.drawMs(20));
  console.log(`measure: ${agents} agents; server listening after ${serverMs} ms; first frame after ${firstFrameMs} ms (page load to drawn); ` +
    `redraw ${drawMs.toFixed(2)} ms median = ${(1000 / drawMs).toFixed(0)} frames per second`);

  if (args['measure-only'] !== 'true') {
    const frames = (args.frames || '0,300').split(',').map(Number);
    for (const k of frames) {
      await page.evaluate((f) => window.crowddbViewer.seek(f), k);
      await page.waitForFunction((f) => window.crowddbViewer.frame === f && window.crowddbViewer.loaded(), k, { timeout: 60000 });
      const want = truth(k);
      // Probe the canvas at the file's positions: the pixel must have the agent's colour (the
      // disc of radius >= 3 px covers it; agents never overlap, so no other disc does).
      const probes = await page.evaluate((pts) => {
        const c = document.getElementById('scene'), g = c.getContext('2d');
        const dpr = window.devicePixelRatio || 1;
        return pts.map(({ id, x, y }) => {
          const [px, py] = window.crowddbViewer.toScreen(x, y);
          const d = g.getImageData(Math.floor(px * dpr), Math.floor(py * dpr), 1, 1).data;
          return { id, rgb: (d[0] << 16) | (d[1] << 8) | d[2], inside: px >= 0 && py >= 0 && px < c.clientWidth && py < c.clientHeight };
        });
      }, want);
      const held = await page.evaluate(() => window.crowddbViewer.agents().map((a) => [a.id, a.x, a.y]));
      check(held.length === want.length && held.every(([id, x, y], i) => id === want[i].id &&
        Math.abs(x - want[i].x) < 1e-4 && Math.abs(y - want[i].y) < 1e-4),
        `frame ${k}: the page holds the file's ${want.length} agents at the file's positions`);
      const coloured = new Set([0x1f77b4, 0xff7f0e, 0x9e9e9e, 0x9467bd]);
      const bad = probes.filter((p) => !p.inside || !coloured.has(p.rgb));  // fitted: all inside
      check(want.length > 0 && bad.length === 0,
        `frame ${k}: a disc under each of the ${probes.length} agents' positions` +
        (bad.length ? ` (${bad.length} missing, e.g. agent ${bad[0].id}: #${bad[0].rgb.toString(16)})` : ''));
    }
    // The scrubber: a click at three quarters of its length moves the playhead there.
    const range = await page.evaluate(() => [Number(document.getElementById('scrub').min), Number(document.getElementById('scrub').max)]);
    const box = await page.locator('#scrub').boundingBox();
    await page.mouse.click(box.x + box.width * 0.75, box.y + box.height / 2);
    const scrubbed = await page.evaluate(() => window.crowddbViewer.frame);
    const expect = range[0] + 0.75 * (range[1] - range[0]);
    check(Math.abs(scrubbed - expect) <= 0.05 * (range[1] - range[0]) + 1,
      `scrubber: a click at 3/4 shows frame ${scrubbed} (about ${Math.round(expect)} expected)`);
    await page.waitForFunction(() => window.crowddbViewer.loaded(), null, { timeout: 60000 });
    // Hover: the mouse over an agent names it in the tooltip.
    const target = await page.evaluate(() => {
      const a = window.crowddbViewer.agents().find((p) => p.px > 20 && p.py > 20 && p.px < 1200 && p.py < 500);
      return a ? { id: a.id, px: a.px, py: a.py } : null;
    });
    check(target !== null, 'hover: an agent on screen to point at');
    if (target) {
      const canvas = await page.locator('#scene').boundingBox();
      await page.mouse.move(canvas.x + target.px, canvas.y + target.py);
      const hovered = await page.evaluate(() => window.crowddbViewer.hovered());
      const tip = await page.locator('#tip').textContent();
      check(hovered === target.id && tip.includes(`agent ${target.id}`) && await page.locator('#tip').isVisible(),
        `hover: agent ${target.id} is named in the tooltip ("${tip.split('\n')[0]}")`);
    }
    // Play: the playhead advances, and the chart is there.
    await page.evaluate(() => window.crowddbViewer.seek(0));
    await page.click('#play');
    await page.waitForTimeout(1500);
    const played = await page.evaluate(() => window.crowddbViewer.frame);
    await page.click('#play');
    check(played > 0, `play: the playhead moved to frame ${played} in 1.5 s`);
    check(await page.locator('#chart canvas').count() > 0, 'the metrics chart is drawn');
    check(errors.length === 0, `no errors on the page${errors.length ? ': ' + errors[0] : ''}`);
  }
  if (args.screenshot) {
    if (args.at) {  // the frame to show in the picture
      await page.evaluate((f) => window.crowddbViewer.seek(f), Number(args.at));
      await page.waitForFunction(() => window.crowddbViewer.loaded(), null, { timeout: 60000 });
    }
    await page.screenshot({ path: args.screenshot });
    console.log(`screenshot: ${args.screenshot}`);
  }
} finally {
  await browser.close();
  server.kill('SIGTERM');
}
if (failures) {
  console.log(`${failures} check(s) failed`);
  process.exit(1);
}
console.log('all checks passed');
