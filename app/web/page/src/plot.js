// A live plot on a 2-D canvas: a few series over a time window, with pause and scroll back
// through the kept history (the last 10 minutes at the frame rate).
const WINDOW_S = 20;
const KEEP = 18000;

export class Plot {
  constructor(canvas, series, { min = 0, max = 1, limitLine = null } = {}) {
    this.canvas = canvas;
    this.series = series;
    this.min = min;
    this.max = max;
    this.limitLine = limitLine;
    this.t = [];
    this.values = series.map(() => []);
    this.paused = false;
    this.scroll = 1;  // 1: the newest data at the right edge
    this.dirty = true;
  }

  push(t, values) {
    if (this.t.length && t < this.t[this.t.length - 1]) {  // a new run: start over
      this.t = [];
      this.values = this.series.map(() => []);
    }
    this.t.push(t);
    values.forEach((v, i) => this.values[i].push(Number.isFinite(v) ? v : null));
    if (this.t.length > KEEP) {
      this.t.shift();
      this.values.forEach((s) => s.shift());
    }
    if (!this.paused) this.dirty = true;
  }

  setPaused(paused) { this.paused = paused; this.scroll = 1; this.dirty = true; }
  setScroll(f) { this.scroll = f; this.dirty = true; }

  draw() {
    if (!this.dirty) return;
    this.dirty = false;
    const c = this.canvas;
    const w = (c.width = c.clientWidth * devicePixelRatio);
    const h = (c.height = c.clientHeight * devicePixelRatio);
    const g = c.getContext('2d');
    g.clearRect(0, 0, w, h);
    g.font = `${10 * devicePixelRatio}px system-ui`;
    if (!this.t.length) return;
    const first = this.t[0], last = this.t[this.t.length - 1];
    const end = Math.max(first + WINDOW_S, first + (last - first) * this.scroll);
    const start = end - WINDOW_S;
    const x = (t) => ((t - start) / WINDOW_S) * w;
    const y = (v) => h - ((v - this.min) / (this.max - this.min)) * (h - 14 * devicePixelRatio) - 2;
    if (this.limitLine !== null) {
      g.strokeStyle = '#e0505080';
      g.setLineDash([4, 4]);
      g.beginPath(); g.moveTo(0, y(this.limitLine)); g.lineTo(w, y(this.limitLine)); g.stroke();
      g.setLineDash([]);
    }
    this.series.forEach((s, i) => {
      g.strokeStyle = s.color;
      g.lineWidth = 1.5 * devicePixelRatio;
      g.beginPath();
      let pen = false;
      for (let k = 0; k < this.t.length; ++k) {
        const t = this.t[k], v = this.values[i][k];
        if (t < start || t > end || v === null) { pen = false; continue; }
        const yv = y(Math.max(this.min, Math.min(this.max, v)));
        if (pen) g.lineTo(x(t), yv); else g.moveTo(x(t), yv);
        pen = true;
      }
      g.stroke();
      g.fillStyle = s.color;
      g.fillText(s.label, 6 * devicePixelRatio + i * 100 * devicePixelRatio, 11 * devicePixelRatio);
    });
    g.fillStyle = '#8a939c';
    g.fillText(`${start.toFixed(0)}..${end.toFixed(0)} s`, w - 70 * devicePixelRatio, h - 4 * devicePixelRatio);
  }
}
