// radar view page: receives one message at a time over /ws, draws it with plotly.js, then
// acknowledges it so the server sends the next (newest) one. Only glue code lives here: every
// chart is a plotly trace. Counters for tests and the benchmark are kept in window.radarView.
"use strict";

const state = window.radarView = {
  draws: 0, frames: 0, lastSeq: null, drawFps: 0, connected: false, reconnects: 0,
  drawTimes: [], lastHealth: null, drawMs: {},
};
const CONFIG = { displaylogo: false, responsive: true, showSendToCloud: false };
const MARGIN = { l: 55, r: 10, t: 30, b: 40 };
// Fixed tick layout: plotly then skips measuring tick labels for overflow and auto-angles,
// a large share of each redraw's time.
const AXIS = { ticklabeloverflow: "allow", tickangle: 0, automargin: false };
function axis(title, extra) { return { ...AXIS, title: { text: title }, ...extra }; }
const HEALTH_KEYS = ["frames_per_s", "frames_complete", "frames_damaged", "frames_lost",
  "frames_not_shown", "packets_lost", "malformed", "late_packets", "datagrams",
  "stream_restarts", "hw_overflow", "hw_framing", "detections", "objects"];
const ALARMS = new Set(["frames_damaged", "frames_lost", "packets_lost", "malformed",
  "hw_overflow", "hw_framing"]);
let channel = 0;
let ws = null;

function decodeMap(m) {
  // base64 uint8 codes (rows x cols) -> dB values, lo + q * (hi - lo) / 255
  const bin = atob(m.q);
  const step = (m.hi - m.lo) / 255;
  const z = new Array(m.rows);
  for (let r = 0; r < m.rows; r++) {
    const row = new Float32Array(m.cols);
    for (let c = 0; c < m.cols; c++) row[c] = m.lo + bin.charCodeAt(r * m.cols + c) * step;
    z[r] = row;
  }
  return z;
}

function heatmap(div, m, title) {
  if (!m) { Plotly.purge(div); return Promise.resolve(); }
  return Plotly.react(div, [{
    type: "heatmap", z: decodeMap(m), x: m.velocity_mps, y: m.range_m,
    zmin: m.lo, zmax: m.hi, colorscale: "Viridis", colorbar: { title: { text: "dB" }, ticklabeloverflow: "allow" },
    hovertemplate: "v %{x:.2f} m/s<br>r %{y:.1f} m<br>%{z:.1f} dB<extra></extra>",
  }], {
    title: { text: title, font: { size: 13 } }, margin: MARGIN, uirevision: div,
    xaxis: axis("radial velocity (m/s)"), yaxis: axis("range (m)"),
  }, CONFIG);
}

function pointCloud(div, msg) {
  const p = msg.points;
  const vmax = msg.limits.max_velocity_mps;
  const traces = [{
    type: "scatter", mode: "markers", x: p.y, y: p.x, name: "points",
    marker: { size: 8, color: p.v, cmin: -vmax, cmax: vmax, colorscale: "Jet",
              line: { width: 1, color: "#222" },
              colorbar: { title: { text: "m/s" }, ticklabeloverflow: "allow" } },
    text: p.snr.map((s, i) => `v ${p.v[i]} m/s, SNR ${s} dB`),
    hovertemplate: "x %{y:.1f} m, y %{x:.1f} m<br>%{text}<extra></extra>",
  }];
  for (const b of msg.boxes) {
    traces.push({ type: "scatter", mode: "lines", x: b.y, y: b.x, name: b.label,
                  line: { color: "#ff6f00", width: 2 }, hoverinfo: "name" });
  }
  if (msg.boxes.length) {
    traces.push({ type: "scatter", mode: "text", x: msg.boxes.map(b => b.cy),
                  y: msg.boxes.map(b => b.cx), text: msg.boxes.map(b => b.label),
                  textposition: "top center", textfont: { color: "#e65100" },
                  hoverinfo: "skip", name: "labels" });
  }
  const r = msg.limits.max_range_m;
  return Plotly.react(div, traces, {
    title: { text: "point cloud, coloured by radial velocity; GNN objects", font: { size: 13 } },
    margin: MARGIN, showlegend: false, uirevision: "cloud",
    xaxis: axis("y (m, left +)", { range: [r / 2, -r / 2] }),
    yaxis: axis("x (m, forward)", { range: [0, r] }),
  }, CONFIG);
}

function profile(div, msg) {
  const pr = msg.profile;
  if (!pr) { Plotly.purge(div); return Promise.resolve(); }
  return Plotly.react(div, [
    { type: "scatter", mode: "lines", x: pr.range_m, y: pr.db, name: "integrated" },
    { type: "scatter", mode: "markers", x: pr.det_range_m, y: pr.det_db, name: "detections",
      marker: { color: "#c62828", size: 7, symbol: "x" } },
  ], {
    title: { text: "range profile (all channels, all Doppler bins)", font: { size: 13 } },
    margin: MARGIN, showlegend: false, uirevision: "profile",
    xaxis: axis("range (m)"), yaxis: axis("power (dB)"),
  }, CONFIG);
}

function showHealth(h) {
  state.lastHealth = h;
  for (const k of HEALTH_KEYS) {
    const td = document.getElementById("h-" + k);
    const v = h[k];
    td.textContent = typeof v === "boolean" ? (v ? "SET" : "clear") : String(v);
    td.classList.toggle("alarm", ALARMS.has(k) && Boolean(v));
  }
  const ul = document.getElementById("problems");
  ul.replaceChildren(...h.problems.slice(-6).map(t => {
    const li = document.createElement("li"); li.textContent = t; return li;
  }));
  const link = document.getElementById("link");
  const idle = h.link_idle_s !== null && h.link_idle_s > 2;
  const bad = h.hw_overflow || h.hw_framing;
  link.className = "tag " + (bad ? "bad" : idle ? "idle" : "ok");
  link.textContent = bad ? "hardware flag" : idle ? `link idle ${h.link_idle_s} s` : "live";
}

function countDraw() {
  const now = performance.now();
  state.draws += 1;
  state.drawTimes.push(now);
  while (state.drawTimes.length && now - state.drawTimes[0] > 2000) state.drawTimes.shift();
  const n = state.drawTimes.length;
  state.drawFps = n > 1 ? (n - 1) * 1000 / (now - state.drawTimes[0]) : 0;
  document.getElementById("draw_fps").textContent = state.drawFps.toFixed(1);
}

async function timed(name, fn) {
  // time spent per plot, ms (exponential average): read by the benchmark
  const t0 = performance.now();
  await fn();
  const dt = performance.now() - t0;
  state.drawMs[name] = state.drawMs[name] === undefined ? dt : 0.9 * state.drawMs[name] + 0.1 * dt;
}

async function draw(msg) {
  if (msg.type === "frame") {
    document.getElementById("source").textContent = `${msg.source} (${msg.preset})`;
    document.getElementById("frame_id").textContent = msg.frame_id;
    const input = document.getElementById("channel");
    input.max = msg.n_virtual - 1;
    await timed("rd", () => heatmap("plot-rd", msg.rd,
                                      `range-Doppler, virtual channel ${msg.channel}`));
    await timed("nci", () => heatmap("plot-nci", msg.nci,
                                     "range-Doppler, integrated over channels"));
    await timed("cloud", () => pointCloud("plot-cloud", msg));
    await timed("profile", () => profile("plot-profile", msg));
    state.frames += 1;
    state.lastSeq = msg.seq;
    countDraw();
  }
  showHealth(msg.health);
}

// Double buffering: the page acknowledges a message when it starts drawing it, so the server
// prepares and sends the next one meanwhile. At most one message is drawn and one waits.
let pending = null;
let drawing = false;

async function drawLoop() {
  drawing = true;
  while (pending) {
    const msg = pending;
    pending = null;
    if (ws && ws.readyState === WebSocket.OPEN) {
      ws.send(JSON.stringify({ ack: msg.seq ?? null, draw_fps: state.drawFps }));
    }
    try {
      await draw(msg);
    } catch (err) {
      console.error("radar view: draw failed", err);
    }
    await new Promise(resolve => requestAnimationFrame(resolve));  // let the browser paint
  }
  drawing = false;
}

function connect() {
  ws = new WebSocket(`ws://${location.host}/ws`);
  ws.onopen = () => {
    state.connected = true;
    if (channel) ws.send(JSON.stringify({ channel }));
  };
  ws.onmessage = (ev) => {
    pending = JSON.parse(ev.data);  // a message not yet drawn is replaced: newest wins
    if (!drawing) drawLoop();
  };
  ws.onclose = () => {
    state.connected = false;
    state.reconnects += 1;
    document.getElementById("link").textContent = "reconnecting";
    document.getElementById("link").className = "tag idle";
    setTimeout(connect, 1000);
  };
}

document.getElementById("channel").addEventListener("change", (ev) => {
  channel = Math.max(0, parseInt(ev.target.value, 10) || 0);
  if (ws && ws.readyState === WebSocket.OPEN) ws.send(JSON.stringify({ channel }));
});
connect();
