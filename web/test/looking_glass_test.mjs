// The page's Looking Glass pieces (web/src/looking_glass.js), run in Node: calibrations refused as
// the native viewer refuses them, each model's view set, and the fixed-point interleave (the
// shader's arithmetic written out here) against the display formula in double precision.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { test } from 'node:test';
import { interleaveConstants, lookingGlassModel, parseCalibration } from '../src/looking_glass.js';

const here = new URL('.', import.meta.url);
const spatial = readFileSync(new URL('../../examples/looking-glass/spatial-16-landscape-visual.json', here), 'utf8');
const portrait = readFileSync(new URL('../../examples/looking-glass/portrait-visual.json', here), 'utf8');

test('calibrations parse, with their subpixel cells and their model', () => {
  const c = parseCalibration(spatial);
  assert.equal(c.screenW, 3840);
  assert.equal(c.cellPatternMode, 2);
  assert.equal(c.cells.length, 2);
  assert.deepEqual(c.cells[1].dy, [-0.25, -0.25, 0.25]);
  assert.equal(c.model.name, 'Looking Glass 16" Spatial (landscape)');
  assert.deepEqual([c.model.columns, c.model.rows, c.model.viewHeight], [7, 7, 857]);
  const p = parseCalibration(portrait);
  assert.equal(p.cells.length, 0);
  assert.deepEqual([p.model.columns, p.model.rows, p.model.viewHeight], [8, 6, 560]);
  assert.deepEqual(lookingGlassModel('LKG-E0001', 1440, 2560), { name: 'Looking Glass Go', columns: 11, rows: 6, viewHeight: 682 });
  assert.equal(lookingGlassModel('custom', 1920, 1080).columns, 5);
  // The serial is informational: an object without "value" is kept as written, not refused.
  const odd = JSON.parse(portrait);
  odd.serial = { note: 'x' };
  assert.equal(parseCalibration(JSON.stringify(odd)).serial, '{"note":"x"}');
});

test('a quilt larger than the browser allows is refused by name, with views that fit', async () => {
  const { LookingGlassOutput } = await import('../src/looking_glass.js');
  const c = parseCalibration(spatial);  // 7x7 views of 1524x857: 10668x5999
  assert.throws(() => new LookingGlassOutput(c, null, 8192), /larger than this browser allows \(8192 a side\): give lkgview= smaller views, at most 1170x658/);
});

test('bad calibrations are refused by name', () => {
  const with_ = (field, value) => { const j = JSON.parse(spatial); j[field] = value; return JSON.stringify(j); };
  const cases = [
    ['{', /malformed JSON/], ['[1]', /expected a JSON object/],
    [with_('pitch', { value: 'x' }), /"pitch" must be a finite number/], [with_('DPI', { val: 3 }), /"DPI" is an object without "value"/],
    [with_('screenW', 0), /"screenW" must be a whole number of pixels in 1..16384/], [with_('screenH', 1e9), /"screenH"/],
    [with_('slope', 0), /"slope" must have \|slope\|/], [with_('pitch', 1e300), /"pitch" must be > 0 and at most/],
    [with_('invView', 2), /"invView" must be 0 or 1/], [with_('viewCone', 0), /"viewCone"/],
    [with_('verticalAngle', 'x'), /"verticalAngle" must be a finite number/],
    [with_('CellPatternMode', 5), /"CellPatternMode" must be a whole number in 0..4/],
    [with_('subpixelCells', 'x'), /"subpixelCells" must be an array/], [with_('subpixelCells', [1]), /subpixelCells\[0\]: expected an object/],
    [with_('subpixelCells', [{ ROffsetX: 0 }]), /subpixelCells\[0\]: missing required field "ROffsetY"/],
    [with_('subpixelCells', new Array(65).fill(JSON.parse(spatial).subpixelCells[0])), /at most 64 cells/],
  ];
  const far = JSON.parse(spatial);
  far.subpixelCells[0].GOffsetX = 9;
  cases.push([JSON.stringify(far), /"GOffsetX" must be a number within 4 pixels/]);
  for (const [text, message] of cases) assert.throws(() => parseCalibration(text), message, text.slice(0, 80));
});

// The shader's view of a subpixel: the phase in 0.32 fixed point, the view from 16-bit halves.
function shaderView(k, c, views, x, y, i) {
  const cellOf = () => {
    const p = k.pattern;
    const cell = p === 1 ? (x + y) % 2 : p === 2 ? y % 4 : p === 3 ? (y + 2 * (x % 2)) % 4 : p === 4 ? x % 2 : 0;
    return cell % Math.max(k.count, 1);
  };
  let a = (Math.imul(x, k.perX) + Math.imul(y, k.perY) + k.origin + k.cellPhase[cellOf() * 3 + i]) >>> 0;
  if (c.invView) a = ~a >>> 0;
  const hi = a >>> 16, lo = a & 0xffff;
  return Math.min(views - 1, (hi * views + ((lo * views) >>> 16)) >>> 16);
}

// The formula in double precision (docs/RENDERING.md#looking-glass-panels).
function formulaView(c, views, x, y, i) {
  const w = c.screenW, h = c.screenH;
  const pitchEff = c.pitch * w / c.dpi * Math.cos(Math.atan(1 / c.slope)), tilt = h / (w * c.slope);
  let u = (x + 0.5) / w, v = (y + 0.5) / h;
  if (c.cells.length) {
    const p = c.cellPatternMode;
    const cell = (p === 1 ? (x + y) % 2 : p === 2 ? y % 4 : p === 3 ? (y + 2 * (x % 2)) % 4 : p === 4 ? x % 2 : 0) % c.cells.length;
    u += c.cells[cell].dx[i] / w;
    v += c.cells[cell].dy[i] / h;
  } else {
    u += i * (c.flipSubp ? -1 : 1) / (3 * w);
  }
  let a = (u + v * tilt) * pitchEff - c.center;
  a -= Math.floor(a);
  if (c.invView) a = 1 - a;
  const boundary = Math.abs(a * views - Math.round(a * views)) < 1e-4;
  return { view: Math.min(views - 1, Math.floor(a * views)), boundary };
}

test('the fixed-point interleave picks the formula\'s view for every subpixel of a panel', () => {
  for (const text of [spatial, portrait]) {
    const c = parseCalibration(text);  // the whole panel, at its real size
    const views = c.model.columns * c.model.rows, k = interleaveConstants(c);
    let differ = 0;
    for (let y = 0; y < c.screenH; ++y)
      for (let x = 0; x < c.screenW; ++x)
        for (let i = 0; i < 3; ++i) {
          const f = formulaView(c, views, x, y, i);
          if (!f.boundary && shaderView(k, c, views, x, y, i) !== f.view) differ += 1;
        }
    assert.equal(differ, 0, `${c.model.name}: ${differ} subpixels away from a view boundary take another view`);
  }
});
