"use strict";
// The console page: live view (MJPEG), status (server-sent events), controls (JSON POSTs).
// The token, when the console needs one, travels as the cookie the page was given.
const stream = document.getElementById("stream");
const band = document.getElementById("band");
const message = document.getElementById("message");
const statusBody = document.querySelector("#status tbody");
const recordButton = document.getElementById("record");
let latest = null;

function viewWidth() {
  return Math.max(64, Math.min(960, Math.round(stream.parentElement.clientWidth * (window.devicePixelRatio || 1))));
}
stream.src = `stream.mjpg?fps=15&width=${viewWidth()}`;

async function post(path, body) {
  const response = await fetch(path, {
    method: "POST", headers: {"Content-Type": "application/json"}, body: JSON.stringify(body || {}),
  });
  const reply = await response.json().catch(() => ({}));
  message.textContent = response.ok ? `${path.replace("api/", "")}: sent` : `${response.status}: ${reply.error || response.statusText}`;
  return response.ok;
}

for (const name of ["pause", "resume", "recenter"]) {
  document.getElementById(name).addEventListener("click", () => post(`api/${name}`));
}
recordButton.addEventListener("click", () => post("api/record", {on: !(latest && latest.recording && latest.recording.on)}));
document.getElementById("stop").addEventListener("click", () => {
  if (window.confirm("End the run? The gimbal stops and the outputs are kept.")) post("api/stop");
});
document.getElementById("settings").addEventListener("submit", (event) => {
  event.preventDefault();
  const changes = {};
  for (const input of event.target.querySelectorAll("input")) {
    if (input.value !== "" && Number(input.value) !== (latest && latest.settings ? latest.settings[input.name] : null)) {
      changes[input.name] = Number(input.value);
    }
  }
  if (Object.keys(changes).length) post("api/settings", changes);
});

// -- picking the subject: drag a box, or tap a candidate ------------------------------------
function toSource(x, y) {  // page pixels in the view -> source frame pixels
  const rect = band.getBoundingClientRect();
  const [w, h] = latest && latest.frame_size ? latest.frame_size : [rect.width, rect.height];
  return [(x - rect.left) * w / rect.width, (y - rect.top) * h / rect.height];
}
let start = null;
function drawBand(x0, y0, x1, y1) {
  band.width = band.clientWidth; band.height = band.clientHeight;
  const ctx = band.getContext("2d");
  ctx.clearRect(0, 0, band.width, band.height);
  if (x0 === undefined) return;
  const rect = band.getBoundingClientRect();
  ctx.strokeStyle = "#ff0"; ctx.lineWidth = 2; ctx.setLineDash([6, 4]);
  ctx.strokeRect(x0 - rect.left, y0 - rect.top, x1 - x0, y1 - y0);
}
band.addEventListener("pointerdown", (e) => { start = [e.clientX, e.clientY]; band.setPointerCapture(e.pointerId); });
band.addEventListener("pointermove", (e) => { if (start) drawBand(start[0], start[1], e.clientX, e.clientY); });
band.addEventListener("pointerup", (e) => {
  if (!start) return;
  const [a, b] = [toSource(...start), toSource(e.clientX, e.clientY)];
  start = null; drawBand();
  const box = [Math.min(a[0], b[0]), Math.min(a[1], b[1]), Math.abs(b[0] - a[0]), Math.abs(b[1] - a[1])];
  if (box[2] >= 4 && box[3] >= 4) { post("api/select", {box: box.map(Math.round)}); return; }
  const hit = (latest && latest.candidates || []).find(([x, y, w, h]) => b[0] >= x && b[0] <= x + w && b[1] >= y && b[1] <= y + h);
  if (hit) post("api/select", {box: hit.map(Math.round)});
});

// -- status ---------------------------------------------------------------------------------
const fmt = (v, digits = 1) => (v === null || v === undefined ? "–" : typeof v === "number" ? v.toFixed(digits) : String(v));
function rows(s) {
  const bus = s.bus || {};
  const lat = s.latency_ms || {};
  return [
    ["state", `${s.state || "–"}${s.paused ? " (paused)" : ""}`],
    ["frame", `${fmt(s.frame, 0)} of ${s.source || "–"}`],
    ["box", s.box ? s.box.map((v) => Math.round(v)).join(", ") : "–"],
    ["confidence", fmt(s.confidence, 2)],
    ["attitude °", s.attitude_deg ? s.attitude_deg.map((v) => fmt(v)).join(" / ") : "–"],
    ["rates °/s", s.rates_dps ? `yaw ${fmt(s.rates_dps[0])}, pitch ${fmt(s.rates_dps[1])}` : "–"],
    ["loop fps", fmt(s.fps)],
    ["latency ms", `p50 ${fmt(lat.p50)}, p99 ${fmt(lat.p99)}`],
    ["bus", `timeouts ${fmt(bus.timeouts, 0)}, NACKs ${fmt(bus.nacks, 0)}${bus.silent ? ", GIMBAL SILENT" : ""}`],
    ["recording", s.recording && s.recording.on ? "on" : "off"],
    ["viewers", fmt(s.viewers, 0)],
  ];
}
function show(s) {
  latest = s;
  statusBody.replaceChildren(...rows(s).map(([k, v]) => {
    const tr = document.createElement("tr");
    for (const text of [k, v]) { const td = document.createElement("td"); td.textContent = text; tr.append(td); }
    return tr;
  }));
  recordButton.classList.toggle("on", Boolean(s.recording && s.recording.on));
  recordButton.textContent = s.recording && s.recording.on ? "Stop recording" : "Record";
  for (const input of document.querySelectorAll("#settings input")) {
    if (document.activeElement !== input && s.settings && s.settings[input.name] !== undefined) input.value = s.settings[input.name];
  }
}
const events = new EventSource("api/events");
events.onmessage = (e) => show(JSON.parse(e.data));
events.onerror = () => { message.textContent = "connection to the run lost (it may have ended)"; };
