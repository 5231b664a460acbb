// Reference for benchmarks.bench_view (not served to the page): how the page drew a frame
// before the canvas heat maps (main ea510a1): one full Plotly.react per plot per update, heat
// maps as plotly heatmap traces. The benchmark times it on the same message as the page's own
// draw, in the same browser, so the old and new figures are measured side by side.
"use strict";
(() => {
const CONFIG = { displaylogo: false, responsive: true, showSendToCloud: false };
const MARGIN = { l: 55, r: 10, t: 30, b: 40 };
const AXIS = { ticklabeloverflow: "allow", tickangle: 0, automargin: false };
function axis(title, extra) { return { ...AXIS, title: { text: title }, ...extra }; }
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


window.referenceDraw = async (msg) => {
  for (const id of ["plot-rd", "plot-nci"]) {
    const h = document.getElementById(id).heat;
    if (h) h.canvas.hidden = true;
  }
  await heatmap("plot-rd", msg.rd, `range-Doppler, virtual channel ${msg.channel}`);
  await heatmap("plot-nci", msg.nci, "range-Doppler, integrated over channels");
  await pointCloud("plot-cloud", msg);
  await profile("plot-profile", msg);
};
})();
