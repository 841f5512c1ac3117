// docs/WEB.md's recipe, run as a newcomer runs it: the bash block after "<!-- recipe -->", word for
// word, from the repository's folder with a fresh home folder, then the address it prints opened in
// headless Chromium. Passes when the page holds the whole volume and the scene with no error and
// no warning. Everything the recipe started (its process group) is stopped at the end.
// Usage: node recipe_test.mjs REPOSITORY WORK_DIR
import { spawn } from 'node:child_process';
import { readFileSync, writeFileSync, mkdirSync, rmSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { chromium } from 'playwright-core';

const [repo, work] = process.argv.slice(2).map((p) => resolve(p));
if (!work) throw new Error('usage: node recipe_test.mjs REPOSITORY WORK_DIR');
rmSync(work, { recursive: true, force: true });
const home = join(work, 'home');
mkdirSync(home, { recursive: true });

const doc = readFileSync(join(repo, 'docs', 'WEB.md'), 'utf8');
const block = /<!-- recipe -->\s*```bash\n([\s\S]*?)```/.exec(doc);
if (!block) { console.error('FAILED: docs/WEB.md has no "<!-- recipe -->" bash block'); process.exit(1); }
writeFileSync(join(work, 'recipe.sh'), block[1]);

let recipe = null;
function stop() {
  if (recipe) try { process.kill(-recipe.pid, 'SIGTERM'); } catch {}
}
process.on('exit', stop);
const deadline = setTimeout(() => { console.error('FAILED: over 150 s'); stop(); process.exit(1); }, 150000);

function fail(message, extra = '') {
  console.error('FAILED: ' + message + extra);
  for (const log of ['nats.log', 'serve.log', 'http.log'])
    try { console.error(`--- ${log}\n` + readFileSync(join(home, 'probecast-web', log), 'utf8').slice(-2000)); } catch {}
  stop();
  process.exit(1);
}

// The block runs in bash with its own process group, so its background servers can be stopped.
const out = [];
recipe = spawn('bash', ['-e', join(work, 'recipe.sh')], { cwd: repo, detached: true, env: { ...process.env, HOME: home },
                                                         stdio: ['ignore', 'pipe', 'pipe'] });
recipe.stdout.on('data', (d) => out.push(d));
recipe.stderr.on('data', (d) => out.push(d));
const code = await new Promise((r) => recipe.on('exit', r));
const text = Buffer.concat(out).toString();
if (code !== 0) fail(`the recipe exited ${code}`, '\n' + text);
const address = /^open (\S+)$/m.exec(text)?.[1];
if (!address) fail('the recipe printed no address to open', '\n' + text);
console.log('ok: the recipe ran and printed ' + address.replace(/#token=.*/, '#token=…'));

const browser = await chromium.launch({
  executablePath: process.env.PROBECAST_CHROMIUM || '/usr/bin/chromium',
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--disable-background-networking',
    '--disable-component-update', '--disable-sync', '--no-first-run'],
});
try {
  const page = await browser.newPage({ viewport: { width: 320, height: 240 } });
  const lines = [];
  page.on('console', (m) => lines.push(m.text()));
  page.on('pageerror', (e) => lines.push('page error: ' + e.message));
  // The servers were started in the background: the page may come up before they do.
  for (let i = 0; ; ++i) {
    try { await page.goto(address); break; } catch (e) {
      if (i > 30) fail('the page did not open: ' + e.message);
      await new Promise((r) => setTimeout(r, 500));
    }
  }
  const end = Date.now() + 90000;
  let s;
  for (;;) {
    s = await page.evaluate(() => ({ ...window.probecast, text: document.getElementById('status').textContent }));
    if (s.sceneLoaded && s.bricks > 0 && s.bricksHeld === s.bricks && s.frames > 10 && !s.error && !s.warning) break;
    if (Date.now() > end) fail('the page did not come up whole', '\nstatus: ' + s.text + '\nconsole: ' + lines.slice(-10).join('\n'));
    await new Promise((r) => setTimeout(r, 250));
  }
  await page.screenshot({ path: join(work, 'page.png') });
  console.log(`ok: the page holds the stream's volume (${s.bricksHeld} bricks, checksum ${s.checksum}) and its scene, no error, no warning`);
  console.log('web recipe ok');
} finally {
  await browser.close().catch(() => {});
  clearTimeout(deadline);
  stop();
}
