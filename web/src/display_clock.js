// The page's display clock, as the native client's (service/client: serverSceneTime, DisplayClock):
// the producer's wall clock is this machine's minus an offset, estimated from the messages (the
// smallest receive − producer stamp of the most recent 64, so one-way delay included; clocks that
// disagree by minutes still give the right scene time); the scene time drawn is the newest state's
// run on at its rate, held where it would step back by less than one second of playback (small
// corrections never run the picture backwards) and followed at once when it jumps ahead or is
// more than a second behind (a stream that restarted or rewound). No DOM: web/test runs it in Node.

export class DisplayClock {
  constructor() {
    this.samples = [];
    this.next = 0;
    this.started = false;
    this.last = 0;
  }

  // A message received at localUs (this machine's wall clock, µs since 1970) whose state the
  // producer stamped at stampUs (its wall clock).
  sample(localUs, stampUs) {
    if (!Number.isFinite(localUs) || !Number.isFinite(stampUs) || stampUs <= 0) return;
    const s = localUs - stampUs;
    if (this.samples.length < 64) this.samples.push(s);
    else this.samples[this.next++ % 64] = s;
  }

  offsetUs() { return this.samples.length ? Math.min(...this.samples) : 0; }

  // The scene time to draw at local time localUs, from the newest state: its scene time, rate
  // (scene seconds per second) and the producer's clock stamp at that time.
  at(time, rate, clockUs, localUs) {
    const target = time + rate * (localUs - this.offsetUs() - clockUs) * 1e-6;
    const second = Math.abs(rate);
    if (!this.started || target >= this.last || this.last - target > second || second === 0) this.last = target;
    this.started = true;
    return this.last;
  }
}
