// The curve recorder (manual 6.7): up to five variables against time, display length
// 10-9999 s with 150 values per display, an archive of the display length up to about
// three times it (at most 500 records), a reading line, the bars of rule effectiveness
// over the output's singletons with the centre of gravity.  Curves are scaled to their
// own range (the manual) or, with "shared axis", curves of one quantity (one unit) share
// one.  Sources: test signals (off line; the outputs read "???" while a curve drives an
// input, manual 6.7), a simulated process (issue 9: the display holds the whole run and
// the recorder stops at its end), a running runtime.
import { state, on, inputs, outputs, range, body, fmt, num, niceTicks, status, isInput } from "./state.js";
import { post, del } from "./api.js";
import { $, el, plot, openDialog, COLORS } from "./ui.js";
import { setTrajectory } from "./surface.js";
import { online } from "./online.js";
import { bases, stacks } from "./rulebars.js";

const POINTS = 150;
const MAX_RECORDS = 500;
let archive = []; // [{t, v: {name: value}}]
let running = null;
let t0 = 0; // left edge of the display
let simTime = 0; // recorder time reached
let k = 0; // samples taken
let busy = false;
let sim = null; // {id, info, config}
let simTrace = null; // full-resolution fuzzy signals for the 3D overlay
let configs = [];
let selectedCurve = 0;
let lastBars = 0;

function rec() {
  return (state.settings.recorder ||= { curves: [], length: 60, signals: {} });
}
const source = () => $("#rec-source").value;
const length = () => rec().length || 60;
const dt = () => length() / POINTS;
/** The archive length in seconds: the display length up to three times it (manual 6.7). */
const archiveLength = () => Math.max(length(), Math.min(3 * length(), rec().archive || 3 * length()));
/** Records the archive holds: its length over the sampling time, at most 500. */
const archiveRecords = () => Math.min(MAX_RECORDS, Math.round(archiveLength() / dt()));

/** The unit of a recorded column, when the plant knows it: its own, that of the signal a
 * fuzzy input reads as it is, or that of a column drawn in the same panel of the loop
 * configuration ([plot] panels: a setpoint beside its measurement). */
function unitOf(name) {
  if (source() !== "sim" || !sim) return null;
  const own = columnUnit(name);
  if (own) return own;
  const config = configs.find((c) => c.path === rec().loop) || {};
  const base = name.startsWith("fb.") ? name.slice(3) : null;
  const mapped = base && ((config.inputs || {})[base] || (config.outputs || {})[base]);
  return typeof mapped === "string" ? expressionUnit(mapped, columnUnit) : null;
}

function columnUnit(name) {
  const units = sim.info.units || {};
  if (units[name]) return units[name];
  for (const panel of sim.info.panels || []) {
    if (!panel.includes(name)) continue;
    const mate = panel.find((c) => units[c]);
    if (mate) return units[mate];
  }
  return null;
}

/** The unit of a sum or difference of columns of one unit ("target - position": m), else
 * null (a product or a mix of units has no unit the recorder could share an axis with). */
function expressionUnit(text, unitOfColumn) {
  if (!/^[\sA-Za-z0-9_.+\-()]+$/.test(text)) return null;
  const names = text.match(/[A-Za-z_][A-Za-z0-9_.]*/g) || [];
  const found = new Set(names.map((n) => unitOfColumn(n)));
  return names.length && found.size === 1 && !found.has(null) ? [...found][0] : null;
}

/** Curves of one quantity share an axis unless the user turned it off. */
const sharing = () => rec().shared !== false;

function format(name, v) {
  const [lo, hi] = ownScale(name);
  const unit = unitOf(name);
  const text = fmt(v, 4, hi - lo);
  return unit ? `${text} ${unit}` : text;
}

function available() {
  if (source() === "sim" && sim) return sim.info.columns.filter((c) => c !== "t");
  if (source() === "online" && online.detail) return [...Object.keys(online.detail.inputs || {}), ...Object.keys(online.detail.outputs || {})];
  return [...inputs(), ...outputs()].map((v) => v.name);
}

function fuzzyName(name) {
  return name.startsWith("fb.") ? name.slice(3) : name;
}

/** The range a curve is drawn over: shared with the curves of the same quantity when the
 * shared axis is on. */
function scale(name) {
  if (!sharing()) return ownScale(name);
  const unit = unitOf(name);
  const key = unit || (isFuzzy(name) ? `range ${ownScale(name).join(" ")}` : null);
  if (!key) return ownScale(name);
  let lo = Infinity;
  let hi = -Infinity;
  for (const other of rec().curves) {
    const otherUnit = unitOf(other);
    const otherKey = otherUnit || (isFuzzy(other) ? `range ${ownScale(other).join(" ")}` : null);
    if (otherKey !== key) continue;
    const [a, b] = ownScale(other);
    lo = Math.min(lo, a);
    hi = Math.max(hi, b);
  }
  return [lo, hi];
}

function isFuzzy(name) {
  const base = fuzzyName(name);
  return [...inputs(), ...outputs()].some((v) => v.name === base) && (source() !== "sim" || name.startsWith("fb."));
}

function ownScale(name) {
  const base = fuzzyName(name);
  if ([...inputs(), ...outputs()].some((v) => v.name === base) && (source() !== "sim" || name.startsWith("fb."))) return range(base);
  let lo = Infinity;
  let hi = -Infinity;
  for (const r of archive) {
    const v = r.v[name];
    if (typeof v === "number") {
      lo = Math.min(lo, v);
      hi = Math.max(hi, v);
    }
  }
  if (!Number.isFinite(lo)) return [0, 1];
  if (hi - lo < 1e-9) return [lo - 1, hi + 1];
  const pad = (hi - lo) * 0.05;
  return [lo - pad, hi + pad];
}

// --- curve and signal selection --------------------------------------------------------

function renderCurves() {
  const names = available();
  const r = rec();
  r.curves = (r.curves || []).filter((c) => names.includes(c)).slice(0, 5);
  if (!r.curves.length) r.curves = names.slice(0, Math.min(5, names.length));
  const tbody = $("#rec-curves tbody");
  tbody.replaceChildren();
  for (let i = 0; i < 5; i++) {
    const radio = el("input", { type: "radio", name: "rec-curve", checked: i === selectedCurve, "aria-label": `curve ${i + 1}` });
    radio.addEventListener("change", () => {
      selectedCurve = i;
      draw();
    });
    const select = el("select", { "aria-label": `curve ${i + 1} variable`, id: `rec-curve-${i}` }, el("option", { value: "" }, "—"), ...names.map((n) => el("option", { value: n, selected: r.curves[i] === n }, n)));
    select.addEventListener("change", () => {
      const list = [...r.curves];
      list[i] = select.value;
      r.curves = list.filter(Boolean);
      renderCurves();
      draw();
    });
    tbody.append(el("tr", { style: `--c:${COLORS[i]}` }, el("td", {}, radio, el("span", { class: "swatch" })), el("td", {}, select), el("td", { class: "num", id: `rec-cur-${i}` }, "")));
  }
  const outs = source() === "sim" ? outputs().map((v) => v.name) : outputs().map((v) => v.name);
  const bar = $("#rec-bar-output");
  if (!outs.includes(r.bar_output)) r.bar_output = outs[0];
  bar.replaceChildren(...outs.map((n) => el("option", { value: n, selected: n === r.bar_output }, n)));
}

function signalOf(name) {
  const r = rec();
  r.signals ||= {};
  const s = r.signals[name];
  return s ? { kind: "constant", value: 0, ...s } : { kind: "constant", value: (range(name)[0] + range(name)[1]) / 2 };
}

function describe(s) {
  if (s.kind === "constant") return `Constant ${fmt(s.value)}`;
  if (s.kind === "triangle") return `Curve ${fmt(s.min)}…${fmt(s.max)}, ${fmt(s.periods)} per., ${fmt(s.duty)} %, ${fmt(s.phase)} %`;
  return s.kind[0].toUpperCase() + s.kind.slice(1);
}

function renderSignals() {
  const row = $("#rec-test");
  row.replaceChildren(el("span", { class: "hint" }, "Curve parameters:"));
  for (const v of inputs()) {
    const button = el("button", { id: `rec-sig-${v.name}`, title: "set the test signal" }, `${v.name}: ${describe(signalOf(v.name))}`);
    button.addEventListener("click", () => editSignal(v.name));
    row.append(button);
  }
  row.append(el("span", { class: "sep" }), el("span", { class: "outputs-now", id: "rec-outputs-now" }, ""));
  outputsNow();
}

/** The outputs for the test signals as the "Curve parameters" dialog shows them: their
 * values when every input is a constant, "???" as soon as a curve drives an input
 * (manual 6.7: they are no longer single values). */
async function outputsNow() {
  const box = $("#rec-outputs-now");
  if (!box || !state.doc) return;
  const signals = inputs().map((v) => [v.name, signalOf(v.name)]);
  const curve = signals.some(([, s]) => s.kind === "triangle");
  if (curve) {
    box.replaceChildren(...outputs().map((o) => el("span", { class: "out-now", "data-output": o.name, title: "an input is driven by a curve: the output is not a single value" }, `${o.name} = ???  `)));
    return;
  }
  const point = {};
  for (const [name, s] of signals) {
    const [lo, hi] = range(name);
    point[name] = s.kind === "constant" ? s.value : s.kind === "minimum" ? lo : s.kind === "maximum" ? hi : 0;
  }
  try {
    const e = await post("/api/explain", body({ inputs: point }), { quiet: true });
    box.replaceChildren(...e.outputs.map((o) => el("span", { class: "out-now", "data-output": o.name, "data-value": o.value ?? "" }, `${o.name} = ${format(o.name, o.value)}  `)));
  } catch (_) {
    box.textContent = "";
  }
}

async function editSignal(name) {
  const s = { ...signalOf(name) };
  const [lo, hi] = range(name);
  $("#sig-input").textContent = name;
  $("#sig-kind").value = s.kind;
  $("#sig-value").value = s.value ?? (lo + hi) / 2;
  $("#sig-min").value = s.min ?? lo;
  $("#sig-max").value = s.max ?? hi;
  $("#sig-periods").value = s.periods ?? 1;
  $("#sig-duty").value = s.duty ?? 50;
  $("#sig-phase").value = s.phase ?? 0;
  const read = () => ({
    kind: $("#sig-kind").value,
    value: parseFloat($("#sig-value").value) || 0,
    min: parseFloat($("#sig-min").value),
    max: parseFloat($("#sig-max").value),
    periods: Math.max(0.01, parseFloat($("#sig-periods").value) || 1),
    duty: Math.max(0, Math.min(100, parseFloat($("#sig-duty").value) || 0)),
    phase: Math.max(0, Math.min(100, parseFloat($("#sig-phase").value) || 0)),
  });
  const preview = async () => {
    const sig = read();
    $("#sig-triangle").disabled = sig.kind !== "triangle";
    $("#sig-value").disabled = sig.kind !== "constant";
    const times = Array.from({ length: POINTS }, (_, i) => i * dt());
    try {
      const res = await post("/api/record", body({ signals: { [name]: clean(sig, lo, hi) }, times, length: length(), reset: true }));
      plot($("#sig-preview"), [{ x: res.t, y: res.values[name], mode: "lines", line: { color: COLORS[0] } }], { margin: { l: 40, r: 10, t: 10, b: 30 }, yaxis: { range: [lo, hi] } }, { staticPlot: true });
    } catch (err) {
      status(err.message, "error");
    }
  };
  const dialog = $("#dlg-signal");
  const handler = () => preview();
  dialog.addEventListener("change", handler);
  preview();
  const answer = await openDialog("#dlg-signal", $("#sig-kind"));
  dialog.removeEventListener("change", handler);
  if (answer !== "ok") return;
  rec().signals[name] = clean(read(), lo, hi);
  renderSignals();
}

function clean(sig, lo, hi) {
  const out = { kind: sig.kind };
  if (sig.kind === "constant") out.value = sig.value;
  if (sig.kind === "triangle") Object.assign(out, { min: Number.isFinite(sig.min) ? sig.min : lo, max: Number.isFinite(sig.max) ? sig.max : hi, periods: sig.periods, duty: sig.duty, phase: sig.phase });
  return out;
}

// --- simulated process ----------------------------------------------------------------

async function renderSim() {
  const row = $("#rec-sim");
  row.replaceChildren();
  try {
    configs = (await fetch(`/api/sim/configs?current=${encodeURIComponent(state.path || "")}`).then((r) => r.json())).configs || [];
  } catch (_) {
    configs = [];
  }
  if (!configs.length) {
    row.append(el("span", { class: "hint" }, "No loop configuration (TOML with a [plant] table, docs/sim.md) in the project directory."));
    return;
  }
  const r = rec();
  if (!configs.some((c) => c.path === r.loop)) r.loop = configs[0].path;
  const select = el("select", { id: "rec-loop", "aria-label": "plant" }, ...configs.map((c) => el("option", { value: c.path, selected: c.path === r.loop }, `${c.title} (${c.plant}${c.matches ? ", this controller" : ""})`)));
  select.addEventListener("change", () => {
    r.loop = select.value;
    const chosen = configs.find((x) => x.path === r.loop);
    if (chosen && chosen.duration) setLength(Math.ceil(chosen.duration));
    renderSim();
  });
  row.append(el("label", {}, "Plant ", select));
  const c = configs.find((x) => x.path === r.loop);
  const box = el("details", { class: "params" }, el("summary", {}, "Plant parameters and setpoints"));
  for (const p of c.parameters) {
    box.append(el("label", { title: p.doc }, `${p.name} [${p.unit}] `, el("input", { type: "number", step: "any", value: p.value, size: 7, "data-param": p.name })));
  }
  for (const [name, value] of Object.entries(c.setpoints)) {
    box.append(el("label", {}, `setpoint ${name} `, el("input", { type: "number", step: "any", value, size: 7, "data-setpoint": name })));
  }
  row.append(box, el("span", { class: "hint" }, ` inputs: ${Object.entries(c.inputs).map(([k, v]) => `${k} = ${v}`).join(", ")}`));
}

async function startSim() {
  const r = rec();
  const parameters = {};
  const setpoints = {};
  for (const input of document.querySelectorAll("#rec-sim [data-param]")) {
    const v = parseFloat(input.value);
    if (Number.isFinite(v)) parameters[input.dataset.param] = v;
  }
  for (const input of document.querySelectorAll("#rec-sim [data-setpoint]")) {
    const v = parseFloat(input.value);
    if (Number.isFinite(v)) setpoints[input.dataset.setpoint] = v;
  }
  if (sim) del(`/api/sim/${sim.id}`).catch(() => {});
  const info = await post("/api/sim/start", body({ config: r.loop, parameters, setpoints }));
  sim = { id: info.id, info };
  simTrace = Object.fromEntries(info.columns.map((c) => [c, []]));
  const fuzzy = [...info.fuzzy.inputs, ...info.fuzzy.outputs].map((n) => `fb.${n}`);
  const measured = info.columns.filter((c) => c !== "t" && !c.startsWith("fb."));
  r.curves = [...fuzzy, ...measured].filter((c) => info.columns.includes(c)).slice(0, 5);
}

// --- sampling ----------------------------------------------------------------------

async function sample() {
  if (busy || !running) return;
  busy = true;
  const session = running;
  try {
    const speed = source() === "online" ? 1 : +$("#rec-speed").value;
    simTime += 0.1 * speed;
    const due = Math.floor(simTime / dt()) + 1 - k;
    if (due <= 0) return;
    const n = Math.min(due, 500);
    if (source() === "test") {
      const times = Array.from({ length: n }, (_, i) => (k + i) * dt());
      // every input's signal as its button shows it (an input never set: the middle of its range)
      const signals = Object.fromEntries(inputs().map((v) => [v.name, signalOf(v.name)]));
      const res = await post("/api/record", body({ signals, times, length: length(), reset: k === 0 }));
      if (session !== running) return; // stopped meanwhile: the recording ended at Stop
      res.t.forEach((t, i) => push(t, Object.fromEntries(Object.entries(res.values).map(([name, vs]) => [name, vs[i]]))));
    } else if (source() === "sim") {
      // never past the configuration's duration: the run ends at the display's right edge
      const reached = archive.length ? archive[archive.length - 1].t : 0;
      const seconds = Math.min(n * dt(), Math.max(sim.info.period || 0.01, (sim.info.duration || Infinity) - reached));
      const res = await post("/api/sim/step", { id: sim.id, seconds });
      if (session !== running) return;
      const rows = res.rows;
      const count = rows.t.length;
      for (const [c, vs] of Object.entries(rows)) simTrace[c].push(...vs);
      // keep the rows at the recorder's sampling instants
      for (let i = 0; i < count; i++) {
        const t = rows.t[i];
        if (t + 1e-9 >= k * dt()) push(t, Object.fromEntries(Object.keys(rows).map((c) => [c, rows[c][i]])));
      }
      shareTrajectory();
      if (sim.info.duration && res.t >= sim.info.duration - 1e-9) {
        draw();
        stop();
        status(`the simulated run is complete (${fmt(sim.info.duration)} s, the configuration's duration): move the reading line, or Start again`);
        return;
      }
    } else {
      const detail = await post("/api/online/read", { url: online.url, token: online.token || null, instance: online.instance });
      if (session !== running) return;
      online.detail = detail;
      push(k * dt(), { ...detail.inputs, ...detail.outputs });
    }
    draw();
    if (Date.now() - lastBars > 300) {
      lastBars = Date.now();
      bars(archive[archive.length - 1]);
    }
  } catch (err) {
    stop();
    status(err.message, "error");
  } finally {
    busy = false;
  }
}

function push(t, values) {
  archive.push({ t, v: values });
  while (archive.length > archiveRecords()) archive.shift();
  k++;
  while (t > t0 + length()) t0 += length() / 4; // the manual's shift by a quarter
}

function shareTrajectory() {
  const fuzzy = sim.info.fuzzy;
  const points = {};
  for (const n of [...fuzzy.inputs, ...fuzzy.outputs]) points[n] = simTrace[`fb.${n}`];
  setTrajectory({ points });
}

// --- drawing ---------------------------------------------------------------------------

function windowRecords() {
  return archive.filter((r) => r.t >= t0 - 1e-9 && r.t <= t0 + length() + 1e-9);
}

function readingRecord() {
  const t = t0 + (+$("#rec-read").value) * dt();
  let best = null;
  for (const r of archive) if (!best || Math.abs(r.t - t) < Math.abs(best.t - t)) best = r;
  return best;
}

function draw() {
  const r = rec();
  const shown = windowRecords();
  const sel = r.curves[selectedCurve] || r.curves[0];
  const [lo, hi] = sel ? scale(sel) : [0, 1];
  const ticks = niceTicks(lo, hi, 5); // round values of the selected curve's scale
  const selColour = COLORS[Math.max(0, r.curves.indexOf(sel))];
  // which curves the labels hold for: the selected one and those drawn on its scale; the
  // others (another quantity, or sharing off) are dotted: the labels are not theirs
  const onAxis = r.curves.filter((c) => sel && scale(c)[0] === lo && scale(c)[1] === hi);
  const traces = r.curves.map((name, i) => {
    const [a, b] = scale(name);
    return { x: shown.map((x) => x.t), y: shown.map((x) => (typeof x.v[name] === "number" ? (x.v[name] - a) / (b - a) : null)), mode: "lines", line: { color: COLORS[i], width: i === selectedCurve ? 2.5 : 1.5, dash: onAxis.includes(name) ? "solid" : "dot" }, name, hoverinfo: "skip" };
  });
  const stopped = !running;
  const reading = stopped && archive.length ? readingRecord() : null;
  const shapes = reading ? [{ type: "line", x0: reading.t, x1: reading.t, y0: -0.02, y1: 1.02, line: { color: "#333", width: 1.5 } }] : [];
  plot($("#rec-chart"), traces, {
    xaxis: { range: [t0, t0 + length()], title: { text: "time [s]" } },
    yaxis: { range: [-0.03, 1.03], tickvals: ticks.map((v) => (v - lo) / (hi - lo)), ticktext: ticks.map((v) => num(v)), tickfont: { color: selColour }, title: { text: sel ? `${onAxis.join(", ")}${unitOf(sel) ? ` [${unitOf(sel)}]` : ""}` : "", font: { color: selColour } } },
    shapes,
    margin: { l: 60, r: 15, t: 10, b: 40 },
  }, { staticPlot: true });
  const last = reading || archive[archive.length - 1];
  r.curves.forEach((name, i) => {
    const cell = $(`#rec-cur-${i}`);
    if (cell) cell.textContent = last ? format(name, last.v[name]) : "";
  });
  for (let i = r.curves.length; i < 5; i++) if ($(`#rec-cur-${i}`)) $(`#rec-cur-${i}`).textContent = "";
  const scroll = $("#rec-scroll");
  const span = archive.length ? archive[archive.length - 1].t - archive[0].t : 0;
  scroll.max = String(Math.max(0, Math.round((span - length()) / dt())));
  scroll.disabled = running !== null || +scroll.max === 0;
  $("#rec-read").disabled = running !== null || !archive.length;
  // the values follow the source: the reading line when stopped, the newest record while running
  $("#rec-values caption").textContent = reading ? "Values at the reading line" : running ? "Values now (running)" : "Values at the reading line";
  if (last) values(last);
  else $("#rec-values tbody").replaceChildren();
  $("#rec-chart").dataset.axis = JSON.stringify({ curve: sel || null, lo, hi, unit: sel ? unitOf(sel) : null, curves: onAxis });
}

function values(record) {
  const tbody = $("#rec-values tbody");
  tbody.replaceChildren(el("tr", {}, el("th", {}, "t [s]"), el("td", { class: "num", id: "rec-val-t", "data-value": record.t }, fmt(record.t, 4, length()))));
  for (const [name, v] of Object.entries(record.v)) {
    if (name === "t") continue;
    tbody.append(el("tr", {}, el("th", {}, name), el("td", { class: "num", id: `rec-val-${name.replace(/\./g, "_")}`, "data-value": v ?? "" }, format(name, v))));
  }
}

async function bars(record) {
  if (!record || !state.doc) return;
  const point = {};
  for (const v of inputs()) {
    const value = source() === "sim" ? record.v[`fb.${v.name}`] : record.v[v.name];
    if (typeof value !== "number") return;
    point[v.name] = value;
  }
  const output = rec().bar_output;
  let e;
  try {
    e = await post("/api/explain", body({ inputs: point }));
  } catch (err) {
    return;
  }
  const b = state.doc.blocks[state.block];
  const blk = b.defuzzify.find((d) => d.variable === output);
  if (!blk) return;
  const curves = (state.report.curves || {})[output] || {};
  const position = (term) => {
    const t = blk.terms.find((x) => x.name === term);
    if (t && t.mf.type === "singleton" && typeof t.mf.value === "number") return t.mf.value;
    const c = curves[term];
    if (c && c.points) {
      const top = Math.max(...c.points.map((p) => p[1]));
      const xs = c.points.filter((p) => p[1] === top).map((p) => p[0]);
      return xs.reduce((a, x) => a + x, 0) / xs.length;
    }
    return null;
  };
  const xs = [];
  const ys = [];
  const labels = [];
  for (const r of e.rules) {
    for (const c of r.conclusions) {
      if (c.variable !== output || c.term === null) continue;
      const x = position(c.term);
      if (x === null) continue;
      xs.push(x);
      ys.push(r.degree * c.weight);
      labels.push(r.label);
    }
  }
  const o = e.outputs.find((x) => x.name === output);
  const [lo, hi] = range(output);
  const width = (hi - lo) / 60;
  const base = bases(xs, ys, stacks(b, output));
  const top = Math.max(1, ...ys.map((y, i) => y + base[i]));
  // the rule numbers above each bar (or stack), horizontal and full size: inside a bar
  // 1/60 of the range wide they were unreadable
  const tops = new Map();
  xs.forEach((x, i) => {
    if (!(ys[i] > 1e-12)) return;
    const t = tops.get(x) || { y: 0, labels: [] };
    t.y = Math.max(t.y, base[i] + ys[i]);
    t.labels.push(labels[i]);
    tops.set(x, t);
  });
  const marks = [...tops].map(([x, t]) => ({ x, y: t.y, text: t.labels.join(", ") }));
  plot($("#rec-bars"), [
    { type: "bar", x: xs, y: ys, base, width: xs.map(() => width), text: labels, textposition: "none", marker: { color: COLORS[0], line: { color: "#fff", width: 1 } }, hoverinfo: "skip" },
    { x: [o.value], y: [-0.06 * top], mode: "markers", marker: { symbol: "triangle-up", size: 14, color: COLORS[1] }, hoverinfo: "skip" },
    { x: marks.map((m) => m.x), y: marks.map((m) => m.y), text: marks.map((m) => m.text), mode: "text", textposition: "top center", textfont: { size: 12, color: "#222" }, hoverinfo: "skip", name: "rules" },
  ], { xaxis: { range: [lo - 0.03 * (hi - lo), hi + 0.03 * (hi - lo)], zeroline: false, title: { text: `${output} = ${format(output, o.value)} (centre of gravity ▲)` } }, yaxis: { range: [-0.12 * top, 1.25 * top], title: { text: "rule effectiveness" } }, barmode: "overlay", showlegend: false, margin: { l: 60, r: 15, t: 10, b: 40 } }, { staticPlot: true });
  $("#rec-bars").dataset.value = String(o.value);
  $("#rec-bars").dataset.rules = JSON.stringify(labels.map((l, i) => [l, ys[i]]));
  $("#rec-bars").dataset.labels = JSON.stringify(marks);
}

// --- start / stop ----------------------------------------------------------------------

async function start() {
  stop();
  archive = [];
  $("#rec-values tbody").replaceChildren(); // nothing of an earlier run or source
  t0 = 0;
  simTime = -0.1 * (source() === "online" ? 1 : +$("#rec-speed").value);
  k = 0;
  try {
    if (source() === "sim") await startSim();
    if (source() === "online" && !(online.url && online.instance)) throw new Error("connect to a runtime and pick an instance on the On line view first");
  } catch (err) {
    status(err.message, "error");
    return;
  }
  renderCurves();
  running = setInterval(sample, 100);
  busy = false;
  $("#rec-start").disabled = true;
  $("#rec-stop").disabled = false;
  $("#view-recorder").dataset.running = "true";
  sample();
  status(`curve recorder running (${source()})`);
}

function stop() {
  if (running) clearInterval(running);
  const was = running !== null;
  running = null;
  $("#rec-start").disabled = false;
  $("#rec-stop").disabled = true;
  $("#view-recorder").dataset.running = "false";
  if (was) {
    $("#rec-read").value = String(Math.min(POINTS - 1, Math.round((archive.length ? archive[archive.length - 1].t - t0 : 0) / dt())));
    draw();
    const r = readingRecord();
    if (r) bars(r);
    status(`curve recorder stopped: ${archive.length} record(s) in the archive; move the reading line`);
  }
}

function setLength(value) {
  const v = Math.max(10, Math.min(9999, value || 60));
  rec().length = v;
  $("#rec-length").value = v;
  setArchive(rec().archive || 3 * v);
}

function setArchive(value) {
  const v = Math.max(length(), Math.min(3 * length(), Math.min(9999, value || 3 * length())));
  rec().archive = Math.round(v * 1000) / 1000;
  $("#rec-archive").value = rec().archive;
  $("#rec-archive").min = length();
  $("#rec-archive").max = Math.min(9999, 3 * length());
  $("#rec-sampling").textContent = `sampling time ${Number((length() / POINTS).toPrecision(4))} s, archive ${archiveRecords()} records`;
}

function layout() {
  const src = source();
  $("#rec-test").hidden = src !== "test";
  $("#rec-sim").hidden = src !== "sim";
  $("#rec-speed").disabled = src === "online";
  if (src === "sim") renderSim();
  renderSignals();
  renderCurves();
  draw();
}

export function init() {
  $("#rec-source").addEventListener("change", () => {
    stop();
    archive = []; // another source: the records of the one before do not belong to it
    t0 = 0;
    layout();
  });
  $("#rec-length").addEventListener("change", (e) => setLength(parseFloat(e.target.value)));
  $("#rec-archive").addEventListener("change", (e) => setArchive(parseFloat(e.target.value)));
  $("#rec-shared").addEventListener("change", (e) => {
    rec().shared = e.target.checked ? undefined : false;
    draw();
  });
  on("model", () => !$("#view-recorder").hidden && source() === "test" && outputsNow());
  $("#rec-start").addEventListener("click", start);
  $("#rec-stop").addEventListener("click", stop);
  $("#rec-stop").disabled = true;
  $("#rec-scroll").addEventListener("input", (e) => {
    const first = archive.length ? archive[0].t : 0;
    t0 = first + +e.target.value * dt();
    draw();
    const r = readingRecord();
    if (r) bars(r);
  });
  $("#rec-read").addEventListener("input", () => {
    draw();
    const r = readingRecord();
    if (r) bars(r);
  });
  $("#rec-bar-output").addEventListener("change", (e) => {
    rec().bar_output = e.target.value;
    const r = running ? archive[archive.length - 1] : readingRecord();
    if (r) bars(r);
  });
  document.addEventListener("keydown", (e) => {
    if (!$("#view-recorder").hidden && e.altKey && e.key.toLowerCase() === "s") {
      e.preventDefault();
      running ? stop() : start();
    }
  });
  on("loaded", () => {
    stop();
    archive = [];
    sim = null;
    const chosen = state.settings.recorder && state.settings.recorder.length;
    // a loop configuration made for this controller: the simulated process is ready
    if ($("#rec-source").dataset.touched) return;
    fetch(`/api/sim/configs?current=${encodeURIComponent(state.path || "")}`)
      .then((r) => r.json())
      .then((res) => {
        const match = (res.configs || []).find((c) => c.matches);
        if (match && !$("#rec-source").dataset.touched) {
          rec().loop = match.path;
          // the display holds the whole run, so the transient stays in view
          if (!chosen) rec().length = Math.max(10, Math.min(9999, Math.ceil(match.duration || 60)));
          $("#rec-source").value = "sim";
          if (!$("#view-recorder").hidden) layout();
        }
      })
      .catch(() => {});
  });
  $("#rec-source").addEventListener("change", () => ($("#rec-source").dataset.touched = "true"));
}

export function shown() {
  if (!state.doc) return;
  setLength(length());
  $("#rec-shared").checked = sharing();
  layout();
}

export function isRunning() {
  return running !== null;
}
export { isInput };
