// The replay player: paints the primitives of spacewar.view.scene, frame by frame, on a
// canvas. No physics and no layout here: every frame was laid out in Python
// (spacewar.view.player_page); this script decodes the frames, paints them and runs the
// controls. Strangers' text is only ever set with textContent or drawn with fillText.
(function () {
  "use strict";

  const data = JSON.parse(document.getElementById("spacewar-replay").textContent);
  const SPEEDS = [0.125, 0.25, 0.5, 1, 2, 4, 8];
  const KINDS = ["dot", "ring", "poly", "fill", "line", "text"];
  const ALIGNS = ["left", "center", "right"];
  const size = data.size, q = data.quantum;
  const canvas = document.getElementById("scope");
  const ctx = canvas.getContext("2d");
  const scrub = document.getElementById("scrub");
  const el = (id) => document.getElementById(id);

  const colours = data.colours.map((c) => "rgb(" + c[0] + "," + c[1] + "," + c[2] + ")");
  let frames = [];
  let frame = 0, speedIndex = 3, playing = false, carry = 0, last = null, drawn = [];

  // -- the data --------------------------------------------------------------------------
  async function unpack(text) {
    const binary = atob(text);
    const bytes = new Uint8Array(binary.length);
    for (let i = 0; i < binary.length; i++) bytes[i] = binary.charCodeAt(i);
    const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("deflate"));
    return JSON.parse(await new Response(stream).text());
  }

  // -- painting: the same primitives paint_pil and the pygame window paint ------------------
  function paint(code) {
    const kind = KINDS[code[0]];
    if (kind === "dot") {
      const x = code[1] / q, y = code[2] / q, r = code[3] / q;
      ctx.fillStyle = colours[code[4]];
      if (r < 0.75) {
        ctx.fillRect(Math.floor(x), Math.floor(y), 1, 1);
      } else {
        ctx.beginPath(); ctx.arc(x, y, r, 0, 2 * Math.PI); ctx.fill();
      }
    } else if (kind === "ring") {
      const r = code[3] / q;
      if (r >= 1) {
        ctx.strokeStyle = colours[code[4]]; ctx.lineWidth = code[5];
        ctx.beginPath(); ctx.arc(code[1] / q, code[2] / q, r, 0, 2 * Math.PI); ctx.stroke();
      }
    } else if (kind === "poly" || kind === "fill") {
      const start = kind === "poly" ? 3 : 2;
      ctx.beginPath();
      ctx.moveTo(code[start] / q, code[start + 1] / q);
      for (let i = start + 2; i < code.length; i += 2) ctx.lineTo(code[i] / q, code[i + 1] / q);
      ctx.closePath();
      if (kind === "poly") {
        ctx.strokeStyle = colours[code[1]]; ctx.lineWidth = code[2]; ctx.stroke();
      } else {
        ctx.fillStyle = colours[code[1]]; ctx.fill();
      }
    } else if (kind === "line") {
      ctx.strokeStyle = colours[code[5]]; ctx.lineWidth = code[6];
      ctx.beginPath(); ctx.moveTo(code[1] / q, code[2] / q);
      ctx.lineTo(code[3] / q, code[4] / q); ctx.stroke();
    } else if (kind === "text") {
      ctx.fillStyle = colours[code[4]];
      ctx.font = (code[6] / q) + "px monospace";
      ctx.textAlign = ALIGNS[code[5]];
      ctx.textBaseline = "top";
      ctx.fillText(data.texts[code[3]], code[1] / q, code[2] / q);
    }
  }

  function draw() {
    ctx.setTransform(canvas.width / size, 0, 0, canvas.height / size, 0, 0);
    ctx.fillStyle = "#000";
    ctx.fillRect(0, 0, size, size);
    data.starfield.forEach(paint);
    drawn = frames[frame] || [];
    drawn.forEach(paint);
    scrub.value = String(frame);
    const seconds = frame / data.fps;
    el("clock").textContent = "frame " + frame + " / " + (data.count - 1) + "  " +
      Math.floor(seconds / 60) + ":" + (seconds % 60).toFixed(1).padStart(4, "0");
  }

  // -- the controls -----------------------------------------------------------------------
  function seek(k) {
    frame = Math.max(0, Math.min(data.count - 1, Math.round(Number(k)) || 0));
    carry = 0;
    draw();
  }
  function setPlaying(on) {
    playing = on && frame < data.count - 1;
    if (on && frame >= data.count - 1) { frame = 0; playing = true; }
    el("play").textContent = playing ? "pause" : "play";
    last = null;
    carry = 0;
  }
  function setSpeed(index) {
    speedIndex = Math.max(0, Math.min(SPEEDS.length - 1, index));
    const s = SPEEDS[speedIndex];
    el("speed").textContent = (s < 1 ? "1/" + Math.round(1 / s) : String(s)) + "x";
  }
  function step(delta) { setPlaying(false); seek(frame + delta); }

  function tick(now) {
    if (playing) {
      if (last !== null) {
        carry += (now - last) / 1000 * data.fps * SPEEDS[speedIndex];
        const whole = Math.floor(carry);
        if (whole > 0) {
          carry -= whole;
          frame = Math.min(data.count - 1, frame + whole);
          if (frame >= data.count - 1) setPlaying(false);
          draw();
        }
      }
      last = now;
    }
    window.requestAnimationFrame(tick);
  }

  function keys(event) {
    if (event.target && event.target.tagName === "INPUT" && event.key !== " ") return;
    const k = event.key;
    if (k === " ") setPlaying(!playing);
    else if (k === "." || k === "ArrowRight") step(1);
    else if (k === "," || k === "ArrowLeft") step(-1);
    else if (k === "]") setSpeed(speedIndex + 1);
    else if (k === "[") setSpeed(speedIndex - 1);
    else if (k === "1") setSpeed(3);
    else if (k === "Home") step(-data.count);
    else if (k === "End") step(data.count);
    else return;
    event.preventDefault();
  }

  function marks() {
    const box = el("marks");
    const span = Math.max(1, data.count - 1);
    data.round_starts.slice(1).forEach((start) => {
      const mark = document.createElement("span");
      mark.style.left = (100 * start / span) + "%";  // CSSOM: allowed by the page's policy
      mark.title = "round starts at frame " + start;
      box.appendChild(mark);
    });
  }

  function header() {
    el("title").textContent = data.names[0] + " vs " + data.names[1];
    el("title").title = data.full_names.join(" vs ");
    el("result").textContent = data.result;
    el("warning").textContent = data.warning;
    const sig = el("signature");
    sig.textContent = "replay " + data.signature_text;
    sig.className = data.signature.replace(" ", "-");
  }

  // the state drawn, for tests and for anyone scripting the page
  window.spacewarPlayer = {
    get frame() { return frame; },
    get count() { return data.count; },
    get playing() { return playing; },
    get speed() { return SPEEDS[speedIndex]; },
    get signature() { return data.signature; },
    roundStarts: data.round_starts.slice(),
    seek: (k) => { setPlaying(false); seek(k); },
    play: () => setPlaying(true),
    pause: () => setPlaying(false),
    // the primitives of the frame on the canvas, in pixels of the size x size scene
    drawn: () => drawn.map((code) => {
      const kind = KINDS[code[0]];
      const px = code.map((v) => v / q);
      if (kind === "text") {
        return { kind, x: px[1], y: px[2], text: data.texts[code[3]], colour: data.colours[code[4]] };
      }
      if (kind === "poly" || kind === "fill") {
        const start = kind === "poly" ? 3 : 2;
        const points = [];
        for (let i = start; i < code.length; i += 2) points.push([px[i], px[i + 1]]);
        return { kind, points, colour: data.colours[code[1]] };
      }
      if (kind === "line") {
        return { kind, points: [[px[1], px[2]], [px[3], px[4]]], colour: data.colours[code[5]] };
      }
      return { kind, x: px[1], y: px[2], r: px[3], colour: data.colours[code[4]] };
    }),
    ready: false,
  };

  async function start() {
    header();
    canvas.width = size;
    canvas.height = size;
    scrub.max = String(data.count - 1);
    marks();
    setSpeed(3);
    frames = await unpack(data.frames);
    scrub.addEventListener("input", () => { setPlaying(false); seek(scrub.value); });
    el("play").addEventListener("click", () => setPlaying(!playing));
    el("back").addEventListener("click", () => step(-1));
    el("forward").addEventListener("click", () => step(1));
    el("slower").addEventListener("click", () => setSpeed(speedIndex - 1));
    el("faster").addEventListener("click", () => setSpeed(speedIndex + 1));
    document.addEventListener("keydown", keys);
    seek(0);
    window.spacewarPlayer.ready = true;
    document.body.dataset.ready = "true";
    window.requestAnimationFrame(tick);
  }
  start().catch((error) => {
    el("result").textContent = "this page could not unpack its match: " + error;
    document.body.dataset.ready = "error";
  });
})();
