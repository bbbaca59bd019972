// The 3D graphic display (manual 6.6): two inputs on X and Y, an output on Z, the other
// inputs as family parameters, rotation, the 4D animation of a third input in steps of
// N %, and the trajectory of the last simulated loop over the surface (issue 9).
import { state, on, emit, inputs, outputs, range, body, fmt, num, niceTicks, status } from "./state.js";
import { post } from "./api.js";
import { $, el, plot } from "./ui.js";
import { gapBoxes } from "./findings.js";

let data = null; // {x, y, frames}
let frame = 0;
let rotating = null;
let animating = null;
let timer = null;
let seq = 0; // surface requests sent
export let trajectory = null; // {x: name, y: name, z: name, points: {name: [...]}} from the recorder

export function setTrajectory(t) {
  trajectory = t;
  $("#sf-trajectory").checked = !!t;
  if (!$("#view-surface").hidden) draw();
}

function settings() {
  return (state.settings.surface ||= {});
}

function fillSelects() {
  const ins = inputs().map((v) => v.name);
  const outs = outputs().map((v) => v.name);
  const s = settings();
  if (!ins.includes(s.x)) s.x = ins[0];
  if (!ins.includes(s.y) || s.y === s.x) s.y = ins.find((n) => n !== s.x) || ins[0];
  if (!outs.includes(s.z)) s.z = outs[0];
  const fill = (sel, names, value) => sel.replaceChildren(...names.map((n) => el("option", { value: n, selected: n === value }, n)));
  fill($("#sf-x"), ins, s.x);
  fill($("#sf-y"), ins, s.y);
  fill($("#sf-z"), outs, s.z);
  const others = ins.filter((n) => n !== s.x && n !== s.y);
  const anim = $("#sf-anim");
  const keep = anim.value;
  anim.replaceChildren(el("option", { value: "" }, "(none)"), ...others.map((n) => el("option", { value: n, selected: n === keep }, n)));
  $("#sf-points").value = s.points || 31;
  const params = $("#sf-params");
  params.replaceChildren();
  s.fixed ||= {};
  for (const name of others) {
    const [lo, hi] = range(name);
    if (!(name in s.fixed) || s.fixed[name] < lo || s.fixed[name] > hi) s.fixed[name] = (lo + hi) / 2;
    const slider = el("input", { type: "range", min: lo, max: hi, step: (hi - lo) / 200, value: s.fixed[name], "aria-label": `family parameter ${name}` });
    const number = el("input", { type: "number", step: "any", value: s.fixed[name], size: 7, "aria-label": `${name} value` });
    const set = (v) => {
      if (!Number.isFinite(v)) return;
      s.fixed[name] = v;
      slider.value = v;
      number.value = v;
      schedule();
    };
    slider.addEventListener("input", () => set(parseFloat(slider.value)));
    number.addEventListener("change", () => set(parseFloat(number.value)));
    params.append(el("label", { class: "param" }, `${name} `, slider, number));
  }
  $("#sf-y").disabled = ins.length < 2;
}

function schedule() {
  clearTimeout(timer);
  timer = setTimeout(refresh, 120);
}

async function refresh() {
  if ($("#view-surface").hidden || !state.doc) return;
  const s = settings();
  if (inputs().length < 2) {
    $("#sf-note").textContent = "The 3D display needs two inputs.";
    return;
  }
  const mine = ++seq;
  const fixed = { ...(s.fixed || {}) };
  try {
    const answer = await post("/api/surface", body({ x: s.x, y: s.y, z: s.z, fixed, points: s.points || 31 }));
    if (mine !== seq) return; // a newer request is under way: its answer is the one to show
    data = answer;
    frame = 0;
    await draw();
    $("#sf-chart").dataset.fixed = JSON.stringify(fixed);
    $("#sf-note").textContent = `${s.z} over ${s.x} and ${s.y}; click a point to explain it.`;
    emit("surface", data);
  } catch (err) {
    $("#sf-note").textContent = err.message;
    status(err.message, "error");
  }
}

function camera() {
  const az = (+$("#sf-rot").value * Math.PI) / 180;
  const el_ = (+$("#sf-elev").value * Math.PI) / 180;
  const r = 2.6;
  return { eye: { x: r * Math.cos(el_) * Math.cos(az), y: r * Math.cos(el_) * Math.sin(az), z: r * Math.sin(el_) } };
}

/** Round ticks inside the range: the ends of X and Y meet at the corners of the floor, where
 * their labels would stand on each other. */
function innerTicks(lo, hi) {
  const span = hi - lo;
  const values = niceTicks(lo, hi, 5).filter((v) => v > lo + span * 0.04 && v < hi - span * 0.04);
  return { tickvals: values, ticktext: values.map((v) => num(v)) };
}

function draw() {
  if (!data) return;
  const s = settings();
  const f = data.frames[frame] || data.frames[0];
  const traces = [{ type: "surface", x: data.x, y: data.y, z: f.z, colorscale: "Viridis", showscale: true, colorbar: { title: { text: s.z }, len: 0.7 }, hovertemplate: `${s.x} %{x:.4g}<br>${s.y} %{y:.4g}<br>${s.z} %{z:.4g}<extra></extra>` }];
  const t = trajectory;
  if ($("#sf-trajectory").checked && t && t.points[s.x] && t.points[s.y] && t.points[s.z]) {
    traces.push({ type: "scatter3d", mode: "lines", x: t.points[s.x], y: t.points[s.y], z: t.points[s.z], line: { color: "#d62728", width: 6 }, name: "loop trajectory", hoverinfo: "skip" });
  }
  const [xl, xh] = range(s.x);
  const [yl, yh] = range(s.y);
  const [zl, zh] = range(s.z);
  // gaps of the output on this plane: their footprint on the floor, outlined (a gap of
  // width 0 is a line), filled where it has an area
  gapBoxes(s.z, s.x, s.y, s.fixed).forEach((g, i) => {
    const [x0, x1] = g.x;
    const [y0, y1] = g.y;
    const name = `gap ${i + 1}: ${g.text}`;
    traces.push({ type: "scatter3d", mode: "lines", x: [x0, x1, x1, x0, x0], y: [y0, y0, y1, y1, y0], z: [zl, zl, zl, zl, zl], line: { color: "#d62728", width: 7 }, name, meta: "gap", hovertemplate: `${name}<extra></extra>` });
    if (x1 > x0 && y1 > y0) traces.push({ type: "surface", x: [x0, x1], y: [y0, y1], z: [[zl, zl], [zl, zl]], showscale: false, opacity: 0.45, colorscale: [[0, "#d62728"], [1, "#d62728"]], name, meta: "gap-area", hoverinfo: "skip" });
  });
  const title = f.value === null || f.value === undefined ? "" : `${$("#sf-anim").value} = ${fmt(f.value)}`;
  return plot($("#sf-chart"), traces, {
    scene: {
      // few ticks, kept apart from the corner where the X and Y labels would meet
      xaxis: { title: { text: s.x }, range: [xl, xh], ...innerTicks(xl, xh), tickfont: { size: 11 } },
      yaxis: { title: { text: s.y }, range: [yl, yh], ...innerTicks(yl, yh), tickfont: { size: 11 } },
      zaxis: { title: { text: s.z }, range: [zl, zh], nticks: 6, tickfont: { size: 11 } },
      camera: camera(),
      aspectmode: "cube",
    },
    margin: { l: 0, r: 0, t: 30, b: 0 },
    title: { text: title, font: { size: 13 } },
    uirevision: "keep",
  });
}

async function toggleAnimation() {
  const button = $("#sf-animate");
  if (animating) {
    clearInterval(animating);
    animating = null;
    button.textContent = "Animation";
    return;
  }
  const input = $("#sf-anim").value;
  const s = settings();
  if (!input) return status("choose a 4D input (one not on X or Y)", "error");
  ++seq;
  try {
    data = await post("/api/surface", body({ x: s.x, y: s.y, z: s.z, fixed: s.fixed || {}, points: Math.min(s.points || 31, 31), animate: input, step_percent: +$("#sf-step").value }));
  } catch (err) {
    return status(err.message, "error");
  }
  frame = 0;
  button.textContent = "Stop";
  animating = setInterval(() => {
    frame = (frame + 1) % data.frames.length;
    draw();
  }, 250);
}

/** The angle of one rotation step: 5 to 45 degrees (manual 6.6); the speed follows. */
function rotationStep() {
  const v = Math.round(+$("#sf-rot-step").value || 10);
  return Math.max(5, Math.min(45, v));
}

function toggleRotation() {
  const button = $("#sf-rotate");
  if (rotating) {
    clearInterval(rotating);
    rotating = null;
    button.textContent = "Rotation";
    return;
  }
  button.textContent = "Stop";
  rotating = setInterval(() => {
    const slider = $("#sf-rot");
    slider.value = (+slider.value + rotationStep()) % 360;
    if (window.Plotly) Plotly.relayout($("#sf-chart"), { "scene.camera": camera() });
  }, 200);
}

export function init() {
  for (const [id, key] of [["#sf-x", "x"], ["#sf-y", "y"], ["#sf-z", "z"]]) {
    $(id).addEventListener("change", (e) => {
      settings()[key] = e.target.value;
      fillSelects();
      schedule();
    });
  }
  $("#sf-points").addEventListener("change", (e) => {
    settings().points = Math.max(5, Math.min(80, parseInt(e.target.value, 10) || 31));
    schedule();
  });
  for (const id of ["#sf-rot", "#sf-elev"]) $(id).addEventListener("input", () => data && window.Plotly && Plotly.relayout($("#sf-chart"), { "scene.camera": camera() }));
  $("#sf-rotate").addEventListener("click", toggleRotation);
  $("#sf-rot-step").addEventListener("change", (e) => (e.target.value = rotationStep()));
  $("#sf-animate").addEventListener("click", toggleAnimation);
  $("#sf-trajectory").addEventListener("change", draw);
  on("findings", () => data && !$("#view-surface").hidden && draw());
  on("model", () => {
    if ($("#view-surface").hidden) return;
    fillSelects();
    schedule();
  });
  on("loaded", () => {
    data = null;
    trajectory = null;
  });
}

let clickBound = false;
export function shown() {
  if (!state.doc) return;
  fillSelects();
  refresh().then(() => {
    const node = $("#sf-chart");
    if (!clickBound && node.on) {
      clickBound = true;
      node.on("plotly_click", (ev) => {
        const p = ev.points && ev.points[0];
        if (!p || p.data.type !== "surface") return;
        const s = settings();
        const values = { ...(s.fixed || {}), [s.x]: p.x, [s.y]: p.y };
        emit("show", { view: "explain", target: { inputs: values } });
      });
    }
  });
}
