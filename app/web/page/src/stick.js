// An on-screen stick: mouse, pen or touch (Pointer Events), x and y in -1..1 (y up positive),
// back to the centre when let go.
export class Stick {
  constructor(element) {
    this.el = element;
    this.knob = element.querySelector('.knob');
    this.x = 0;
    this.y = 0;
    element.addEventListener('pointerdown', (e) => {
      element.setPointerCapture(e.pointerId);
      this.follow(e);
    });
    element.addEventListener('pointermove', (e) => {
      if (element.hasPointerCapture(e.pointerId)) this.follow(e);
    });
    for (const ev of ['pointerup', 'pointercancel', 'lostpointercapture']) {
      element.addEventListener(ev, () => this.set(0, 0));
    }
  }

  follow(e) {
    const r = this.el.getBoundingClientRect();
    const radius = r.width / 2;
    this.set((e.clientX - r.left - radius) / radius, -(e.clientY - r.top - radius) / radius);
  }

  set(x, y) {
    const len = Math.hypot(x, y);
    const k = len > 1 ? 1 / len : 1;
    this.x = x * k;
    this.y = y * k;
    const travel = (this.el.clientWidth - this.knob.offsetWidth) / 2;
    this.knob.style.transform = `translate(${this.x * travel}px, ${-this.y * travel}px)`;
  }
}
