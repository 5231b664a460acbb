// radar view page: receives one message at a time over /ws, draws it with plotly.js, then
// acknowledges it so the server sends the next (newest) one. Only glue code lives here: every
// chart is a plotly trace. Counters for tests and the benchmark are kept in window.radarView.
"use strict";

const state = window.radarView = {
  draws: 0, frames: 0, lastSeq: null, drawFps: 0, connected: false, reconnects: 0,
  drawTimes: [], lastHealth: null, drawMs: {},
  // benchmark hooks: hold = true stops drawing live messages; lastFrame is the newest frame
  // message drawn; drawFrame(msg) draws one message (benchmarks.bench_view times it)
  hold: false, lastFrame: null, drawFrame: null,
  // benchmark hook: serial = true draws the plots one after another, as before 2026-11-23
  // (benchmarks.bench_view compares the display rates in the same run)
  serial: false,
};
const CONFIG = { displaylogo: false, responsive: true, showSendToCloud: false };
const MARGIN = { l: 55, r: 10, t: 30, b: 40 };
// Fixed tick layout: plotly then skips measuring tick labels for overflow and auto-angles,
// a large share of each redraw's time.
const AXIS = { ticklabeloverflow: "allow", tickangle: 0, automargin: false };
function axis(title, extra) { return { ...AXIS, title: { text: title }, ...extra }; }
const HEALTH_KEYS = ["frames_per_s", "frames_complete", "frames_damaged", "frames_lost",
  "frames_not_shown", "packets_lost", "malformed", "late_packets", "datagrams",
  "stream_restarts", "hw_overflow", "hw_framing", "detections", "objects", "stream_kind",
  "cfar_detections", "records", "max_detections", "truncated", "frames_truncated"];
const ALARMS = new Set(["frames_damaged", "frames_lost", "packets_lost", "malformed",
  "hw_overflow", "hw_framing", "truncated", "frames_truncated"]);
let channel = 0;
let ws = null;

// Heat maps: plotly draws the axes, title and colour bar (a placeholder heatmap trace with
// the map's extent and colour range) and is called again only when those change (5 dB grid,
// channel, preset); each frame's cells go into a canvas over the plot area, one pixel per
// cell through a 256-entry lookup table of the trace's own colorscale (codes q are linear
// in dB from lo to hi = zmin to zmax). A full Plotly.react per frame re-runs defaults, axes,
// colour bar and PNG encoding of the image: about 25 ms per map, against < 1 ms here.
function lookupTable(colorscale) {
  // [[fraction, "rgb(...)"|"#rrggbb"], ...] -> Uint32Array(256) of ABGR (little endian RGBA)
  const ctx = document.createElement("canvas").getContext("2d");
  const rgb = colorscale.map(([f, c]) => {
    ctx.fillStyle = c; const h = ctx.fillStyle;  // canonical "#rrggbb"
    return [f, parseInt(h.slice(1, 3), 16), parseInt(h.slice(3, 5), 16),
            parseInt(h.slice(5, 7), 16)];
  });
  const lut = new Uint32Array(256);
  for (let q = 0, k = 0; q < 256; q++) {
    const f = q / 255;
    while (k < rgb.length - 2 && f > rgb[k + 1][0]) k++;
    const [f0, r0, g0, b0] = rgb[k], [f1, r1, g1, b1] = rgb[k + 1];
    const t = f1 > f0 ? Math.min(1, Math.max(0, (f - f0) / (f1 - f0))) : 0;
    lut[q] = (255 << 24 | Math.round(b0 + t * (b1 - b0)) << 16
              | Math.round(g0 + t * (g1 - g0)) << 8 | Math.round(r0 + t * (r1 - r0))) >>> 0;
  }
  return lut;
}

function decodeCodes(m) {
  // base64 uint8 codes, row-major (rows = range bins from 0 up, cols = velocity bins)
  const bin = atob(m.q);
  const q = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) q[i] = bin.charCodeAt(i);
  return q;
}

function half(a) { return a.length > 1 ? (a[1] - a[0]) / 2 : 0.5; }

function heatFrame(div, m, title) {
  // the plotly part: axes over the cells' extent, colour bar lo..hi dB
  const dx = half(m.velocity_mps), dy = half(m.range_m);
  const xr = [m.velocity_mps[0] - dx, m.velocity_mps[m.cols - 1] + dx];
  const yr = [m.range_m[0] - dy, m.range_m[m.rows - 1] + dy];
  return Plotly.react(div, [{
    type: "heatmap", z: [[m.lo, m.hi]], x: [m.velocity_mps[0], m.velocity_mps[m.cols - 1]],
    y: [m.range_m[0]], zmin: m.lo, zmax: m.hi,
    colorscale: "Viridis", hoverinfo: "skip",
    colorbar: { title: { text: "dB" }, ticklabeloverflow: "allow" },
  }], {
    title: { text: title, font: { size: 13 } }, margin: MARGIN, hovermode: false,
    xaxis: axis("radial velocity (m/s)", { range: xr, fixedrange: true }),
    yaxis: axis("range (m)", { range: yr, fixedrange: true }),
  }, CONFIG);
}

function heatCanvas(div) {
  if (div.heat) return div.heat;
  const canvas = document.createElement("canvas");
  canvas.className = "heat";
  const tip = document.createElement("span");
  tip.className = "heat-tip";
  div.append(canvas, tip);
  const h = div.heat = { canvas, tip, key: null, lut: null, m: null, codes: null };
  canvas.addEventListener("mousemove", (ev) => {
    if (!h.m) return;
    const box = canvas.getBoundingClientRect();
    const c = Math.floor((ev.clientX - box.left) / box.width * h.m.cols);
    const r = h.m.rows - 1 - Math.floor((ev.clientY - box.top) / box.height * h.m.rows);
    if (c < 0 || r < 0 || c >= h.m.cols || r >= h.m.rows) return;
    const db = h.m.lo + h.codes[r * h.m.cols + c] * (h.m.hi - h.m.lo) / 255;
    tip.textContent = `v ${h.m.velocity_mps[c].toFixed(2)} m/s, r ${h.m.range_m[r].toFixed(1)} m, `
                      + `${db.toFixed(1)} dB`;
  });
  canvas.addEventListener("mouseleave", () => { tip.textContent = ""; });
  return h;
}

function placeHeat(div) {
  // the canvas covers the plot area exactly (plotly's margins and size)
  const h = div.heat, size = div._fullLayout && div._fullLayout._size;
  if (!h || !size) return;
  Object.assign(h.canvas.style, { left: `${size.l}px`, top: `${size.t}px`,
                                  width: `${size.w}px`, height: `${size.h}px` });
}

async function heatmap(div, m, title, msg) {
  const el = document.getElementById(div);
  if (!m) {  // a detection-record stream: no maps, the detections in their place
    if (el.heat) Object.assign(el.heat, { key: null, m: null, codes: null });
    if (el.heat) el.heat.canvas.hidden = true;
    return div === "plot-nci" ? detectionMap(div, msg) : noMap(div, title);
  }
  const h = heatCanvas(el);
  const key = JSON.stringify([title, m.lo, m.hi, m.rows, m.cols, m.range_m[0],
                              m.range_m[m.rows - 1], m.velocity_mps[0],
                              m.velocity_mps[m.cols - 1]]);
  if (key !== h.key) {
    el.figureKey = null;
    await heatFrame(el, m, title);
    if (!h.lut) h.lut = lookupTable(el._fullData[0].colorscale);
    if (!h.bound) { el.on("plotly_afterplot", () => placeHeat(el)); h.bound = true; }
    placeHeat(el);
    h.key = key;
  }
  const codes = decodeCodes(m);
  if (h.canvas.width !== m.cols || h.canvas.height !== m.rows) {
    h.canvas.width = m.cols;
    h.canvas.height = m.rows;
    h.image = new ImageData(m.cols, m.rows);
  }
  const px = new Uint32Array(h.image.data.buffer);
  const { rows, cols } = m, lut = h.lut;
  for (let r = 0; r < rows; r++) {  // row 0 (range 0) at the bottom
    const src = r * cols, dst = (rows - 1 - r) * cols;
    for (let c = 0; c < cols; c++) px[dst + c] = lut[codes[src + c]];
  }
  h.canvas.getContext("2d").putImageData(h.image, 0, 0);
  h.canvas.hidden = false;
  h.m = m;
  h.codes = codes;
}

// Line and scatter plots: Plotly.react when the figure's frame changes (trace count, axis
// ranges: the key), else Plotly.animate with redraw: false, plotly's fast path that moves the
// traces' points without redrawing axes, titles and colour bars.
const ANIMATE = { transition: { duration: 0 }, frame: { duration: 0, redraw: false },
                  mode: "immediate" };

function update(id, traces, layout, key) {
  const div = document.getElementById(id);
  key = JSON.stringify([traces.length, key]);
  if (div.figureKey === key) {
    if (!traces.length) return Promise.resolve();
    return Plotly.animate(div, { data: traces, traces: traces.map((_, i) => i) }, ANIMATE);
  }
  div.figureKey = key;
  return Plotly.react(div, traces, layout, CONFIG);
}

function noMap(div, title) {
  return update(div, [], {
    title: { text: title, font: { size: 13 } }, margin: MARGIN,
    xaxis: { visible: false }, yaxis: { visible: false },
    annotations: [{ text: "records stream: no cube (no per-channel map)", showarrow: false,
                    xref: "paper", yref: "paper", x: 0.5, y: 0.5 }],
  }, "no map");
}

function detectionMap(div, msg) {
  // what the FPGA's CFAR passed, on the range-Doppler plane: every record (cell) coloured by
  // its integrated power, the points made from them (peaks) ringed
  const p = msg.points, c = msg.cells, vmax = msg.limits.max_velocity_mps;
  const r = msg.limits.max_range_m;
  const traces = [];
  if (c) {
    let lo = Infinity, hi = -Infinity;
    for (const v of c.db) { if (v < lo) lo = v; if (v > hi) hi = v; }
    if (!c.db.length) { lo = 0; hi = 10; }  // a frame without records
    traces.push({
      type: "scatter", mode: "markers", x: c.v, y: c.range, name: "records",
      marker: { size: 6, color: c.db, cmin: 5 * Math.floor(lo / 5), cmax: 5 * Math.ceil(hi / 5),
                colorscale: "Viridis",
                colorbar: { title: { text: "dB" }, ticklabeloverflow: "allow" } },
      text: c.snr.map(s => `CFAR SNR ${s} dB`),
      hovertemplate: "v %{x:.2f} m/s<br>r %{y:.1f} m<br>%{marker.color:.1f} dB, %{text}"
                     + "<extra></extra>",
    });
  }
  traces.push({
    type: "scatter", mode: "markers", x: p.v, y: p.range, name: "points",
    marker: c ? { size: 12, color: "rgba(0,0,0,0)", line: { width: 2, color: "#c62828" } }
      : { size: 8, color: p.snr, cmin: 0, cmax: 40, colorscale: "Viridis",
          line: { width: 1, color: "#222" },
          colorbar: { title: { text: "SNR dB" }, ticklabeloverflow: "allow" } },
    hovertemplate: "point: v %{x:.2f} m/s<br>r %{y:.1f} m<extra></extra>",
  });
  const scale = c ? traces[0].marker.cmin + "," + traces[0].marker.cmax : "snr";
  return update(div, traces, {
    title: { text: c ? "range-Doppler: the FPGA's detections (records; no cube)"
                     : "range-Doppler detections (record stream: no map)", font: { size: 13 } },
    margin: MARGIN, showlegend: false,
    xaxis: axis("radial velocity (m/s)", { range: [-vmax, vmax] }),
    yaxis: axis("range (m)", { range: [0, r] }),
  }, ["detections", r, vmax, scale]);
}

function pointCloud(div, msg) {
  const p = msg.points;
  const vmax = msg.limits.max_velocity_mps;
  const traces = [{
    type: "scatter", mode: "markers", x: p.y, y: p.x, name: "points",
    marker: { size: 8, color: p.v, cmin: -vmax, cmax: vmax, colorscale: "Jet",
              line: { width: 1, color: "#222" },
              colorbar: { title: { text: "m/s" }, ticklabeloverflow: "allow" } },
    text: p.snr.map((s, i) => `v ${p.v[i]} m/s, SNR ${s} dB` +
                    (p.z ? `<br>z ${p.z[i]} m, elevation ${p.el[i]} deg` : "")),
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
  return update(div, traces, {
    title: { text: "point cloud, coloured by radial velocity; GNN objects", font: { size: 13 } },
    margin: MARGIN, showlegend: false, uirevision: "cloud",
    xaxis: axis("y (m, left +)", { range: [r / 2, -r / 2] }),
    yaxis: axis("x (m, forward)", { range: [0, r] }),
  }, [r, vmax]);
}

function profile(div, msg) {
  const pr = msg.profile;
  if (!pr) {  // a detection-record stream without records: each point's SNR over its range
    const p = msg.points, r = msg.limits.max_range_m;
    const top = 10 * Math.ceil(Math.max(10, ...p.snr) / 10) + 5;
    return update(div, [{ type: "scatter", mode: "markers", x: p.range, y: p.snr,
                          name: "detections",
                          marker: { color: "#c62828", size: 7, symbol: "x" } }], {
      title: { text: "detections: SNR over range (record stream: no profile)",
               font: { size: 13 } },
      margin: MARGIN, showlegend: false,
      xaxis: axis("range (m)", { range: [0, r] }), yaxis: axis("SNR (dB)", { range: [0, top] }),
    }, ["records", r, top]);
  }
  const records = pr.kind === "records";
  // y range on a 10 dB grid: the axes stay put from frame to frame
  let lo = Infinity, hi = -Infinity;
  for (const v of pr.db) { if (v < lo) lo = v; if (v > hi) hi = v; }
  if (!pr.db.length) { lo = 0; hi = 10; }
  const yr = [10 * Math.floor(lo / 10) - 5, 10 * Math.ceil(hi / 10) + 5];
  const xr = records ? [0, msg.limits.max_range_m]
    : [pr.range_m[0], pr.range_m[pr.range_m.length - 1]];
  return update(div, [
    records ? { type: "scatter", mode: "markers", x: pr.range_m, y: pr.db, name: "records",
                marker: { color: "#1565c0", size: 5 } }
      : { type: "scatter", mode: "lines", x: pr.range_m, y: pr.db, name: "integrated" },
    { type: "scatter", mode: "markers", x: pr.det_range_m, y: pr.det_db, name: "detections",
      marker: { color: "#c62828", size: 7, symbol: "x" } },
  ], {
    title: { text: records ? "records: integrated power over range (points: x)"
                           : "range profile (all channels, all Doppler bins)",
             font: { size: 13 } },
    margin: MARGIN, showlegend: false, uirevision: "profile",
    xaxis: axis("range (m)", { range: xr }), yaxis: axis("power (dB)", { range: yr }),
  }, [pr.kind, xr, yr]);
}

function showHealth(h) {
  state.lastHealth = h;
  for (const k of HEALTH_KEYS) {
    const td = document.getElementById("h-" + k);
    const v = h[k];
    td.textContent = typeof v === "boolean" ? (v ? "SET" : "clear")
      : v === null || v === "" ? "-" : String(v);
    td.classList.toggle("alarm", ALARMS.has(k) && Boolean(v));
  }
  // the record stream's rows (on-chip detections, records, truncation) only when it is one
  for (const tr of document.querySelectorAll("tr.rec")) tr.hidden = h.stream_kind !== "records";
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
    // the four plots at once: Plotly.animate resolves on the next animation frame, so plots
    // drawn one after another would each wait for a frame of their own (3 frames, 50 ms, a
    // 20 updates/s ceiling however fast the machine); together they share one
    const plots = [
      () => timed("rd", () => heatmap("plot-rd", msg.rd,
                                      `range-Doppler, virtual channel ${msg.channel}`, msg)),
      () => timed("nci", () => heatmap("plot-nci", msg.nci,
                                       "range-Doppler, integrated over channels", msg)),
      () => timed("cloud", () => pointCloud("plot-cloud", msg)),
      () => timed("profile", () => profile("plot-profile", msg)),
    ];
    if (state.serial) {
      for (const plot of plots) await plot();
    } else {
      await Promise.all(plots.map(plot => plot()));
    }
    state.frames += 1;
    state.lastSeq = msg.seq;
    state.lastFrame = msg;
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
    const t0 = performance.now();
    try {
      await draw(msg);
    } catch (err) {
      console.error("radar view: draw failed", err);
    }
    // let the browser paint, unless the draw already waited for an animation frame
    if (state.serial || performance.now() - t0 < 8) {
      await new Promise(resolve => requestAnimationFrame(resolve));
    }
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
    if (state.hold) return;
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

state.drawFrame = draw;
document.getElementById("channel").addEventListener("change", (ev) => {
  channel = Math.max(0, parseInt(ev.target.value, 10) || 0);
  if (ws && ws.readyState === WebSocket.OPEN) ws.send(JSON.stringify({ channel }));
});
connect();
