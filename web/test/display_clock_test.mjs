// The page's display clock (web/src/display_clock.js) in Node: the native client's rules.
import assert from 'node:assert/strict';
import { test } from 'node:test';
import { DisplayClock } from '../src/display_clock.js';

test('clocks minutes apart give the producer\'s scene time, one-way delay included', () => {
  const c = new DisplayClock();
  const skew = 180e6;  // this machine's clock 3 minutes ahead of the producer's
  // Messages stamped at producer times 0, 0.1, 0.2 s arrive 30-80 ms later.
  [30e3, 80e3, 45e3].forEach((delay, i) => c.sample(1e15 + skew + i * 1e5 + delay, 1e15 + i * 1e5));
  assert.equal(c.offsetUs(), skew + 30e3);
  // The newest state: scene time 2.0 at producer clock 1e15 + 2e5, rate 0.5. Drawn 1 s later.
  const t = c.at(2.0, 0.5, 1e15 + 2e5, 1e15 + 2e5 + skew + 1e6);
  assert.ok(Math.abs(t - (2.0 + 0.5 * (1e6 - 30e3) * 1e-6)) < 1e-9, t);
});

test('the picture never runs back a little, but follows a rewind', () => {
  const c = new DisplayClock();
  assert.equal(c.at(5, 1, 0, 0), 5);
  assert.equal(c.at(4.5, 1, 0, 0), 5, 'half a second back: held');
  assert.equal(c.at(5.2, 1, 0, 0), 5.2, 'ahead: followed');
  assert.equal(c.at(1, 1, 0, 0), 1, 'more than a second back: a rewind, followed');
  assert.equal(c.at(0.5, 0, 0, 0), 0.5, 'a still scene: its time');
  c.sample(NaN, 1);
  c.sample(1, 0);
  assert.equal(c.offsetUs(), 0, 'no usable sample: clocks taken to agree');
});
