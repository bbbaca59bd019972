// Input and output editors (manual 6.4): name, value range with the manual's two
// questions, terms (insert, delete, rename, "insert N" evenly spread), points in a table
// and draggable on the chart (singletons move as a line), zoom in five steps.
import { state, on, fb, inputs, outputs, termBlock, range, changed, handles, localCurve, diagnosticsFor, evenTerms, termNames, isIdentifier, isInput, fmt, status } from "./state.js";
import { nameWarning } from "./names.js";
import { $, el, confirmDialog, fillDiagnostics, plot, COLORS } from "./ui.js";

let current = null; // variable name
let term = 0; // index of the selected term
let point = 0; // index of the selected handle
let zoom = 0; // 0..5: the view is 2^zoom times narrower, centred on the selected point
let dragging = null;

const chart = () => $("#mf-chart");

function variableNames() {
  return [...inputs(), ...outputs()].map((v) => v.name);
}

function selected() {
  const blk = current ? termBlock(current) : null;
  return { blk, t: blk && blk.terms[term] ? blk.terms[term] : null };
}

function viewRange() {
  const [lo, hi] = range(current);
  if (!zoom) return [lo, hi];
  const { t } = selected();
  const h = t ? handles(t) : null;
  const centre = h && h[point] ? h[point].x : (lo + hi) / 2;
  const half = (hi - lo) / 2 / 2 ** zoom;
  return [centre - half, centre + half];
}

function renderChart() {
  const node = chart();
  const blk = current ? termBlock(current) : null;
  if (!blk) {
    Plotly.purge(node);
    return;
  }
  const [lo, hi] = range(current);
  const traces = [];
  const serverCurves = (state.report && state.report.curves && state.report.curves[current]) || {};
  blk.terms.forEach((t, i) => {
    const active = i === term;
    const color = COLORS[i % COLORS.length];
    const curve = localCurve(t, lo, hi) || serverCurves[t.name] || {};
    const line = { color, width: active ? 3.5 : 1.5 };
    if (curve.singleton !== undefined) {
      traces.push({ x: [curve.singleton, curve.singleton], y: [0, 1], mode: "lines", line, name: t.name, hoverinfo: "name" });
    } else if (curve.points) {
      traces.push({ x: curve.points.map((p) => p[0]), y: curve.points.map((p) => p[1]), mode: "lines", line, name: t.name, hoverinfo: "name" });
    } else if (curve.spikes) {
      for (const [x, y] of curve.spikes) traces.push({ x: [x, x], y: [0, y], mode: "lines", line, name: t.name });
    }
    if (active) {
      const h = handles(t) || [];
      traces.push({
        x: h.map((p) => p.x),
        y: h.map((p) => (p.singleton ? 1 : p.y)),
        mode: "markers",
        marker: { size: h.map((_, k) => (k === point ? 15 : 10)), color: "#fff", line: { color, width: 2.5 } },
        hoverinfo: "skip",
      });
    }
  });
  const annotations = blk.terms.map((t, i) => {
    const h = handles(t);
    const xs = h ? h.filter((p) => p.singleton || p.y > 0.5).map((p) => p.x) : [];
    const x = xs.length ? xs.reduce((a, b) => a + b, 0) / xs.length : null;
    return x === null ? null : { x, y: 1.08, text: t.name, showarrow: false, font: { color: COLORS[i % COLORS.length], size: i === term ? 13 : 11 } };
  }).filter(Boolean);
  plot(node, traces, {
    xaxis: { range: viewRange(), fixedrange: true, zeroline: false, title: { text: current } },
    yaxis: { range: [-0.05, 1.15], fixedrange: true, title: { text: "degree" } },
    dragmode: false,
    hovermode: false,
    annotations,
    margin: { l: 50, r: 20, t: 10, b: 45 },
  }, { staticPlot: false, displayModeBar: false });
}

function renderTable() {
  const tbody = $("#points-table tbody");
  tbody.replaceChildren();
  const { t } = selected();
  const h = t ? handles(t) : null;
  if (!t) return;
  if (!h) {
    tbody.append(el("tr", {}, el("td", { colspan: 3 }, `${t.mf.type} ${t.mf.kind || ""}: edit in the FCL text`)));
    return;
  }
  h.forEach((p, k) => {
    const x = el("input", { type: "number", step: "any", value: String(p.x), "aria-label": `point ${k + 1} x`, size: 8 });
    x.addEventListener("change", () => {
      const v = parseFloat(x.value);
      if (!Number.isFinite(v)) return;
      p.set(v);
      point = k;
      changed("points");
    });
    let y = el("span", {}, p.singleton ? "—" : fmt(p.y));
    if (t.mf.type === "points") {
      y = el("input", { type: "number", step: "any", min: 0, max: 1, value: String(p.y), "aria-label": `point ${k + 1} degree`, size: 5 });
      y.addEventListener("change", () => {
        const v = parseFloat(y.value);
        if (Number.isFinite(v) && v >= 0 && v <= 1) {
          t.mf.points[k].y = v;
          changed("points");
        }
      });
    }
    tbody.append(el("tr", { class: k === point ? "selected" : null }, el("td", {}, String(k + 1)), el("td", {}, x), el("td", {}, y)));
  });
}

function render() {
  const names = variableNames();
  if (!names.includes(current)) current = names[0] || null;
  const select = $("#var-select");
  select.replaceChildren(...names.map((n) => el("option", { value: n, selected: n === current }, `${isInput(n) ? "input" : "output"}: ${n}`)));
  const blk = current ? termBlock(current) : null;
  if (!blk) {
    renderChart();
    return;
  }
  if (term >= blk.terms.length) term = Math.max(0, blk.terms.length - 1);
  // A field being typed in keeps its text when a check's report redraws the view.
  if (document.activeElement !== $("#var-name")) $("#var-name").value = current;
  const [lo, hi] = range(current);
  if (document.activeElement !== $("#var-min")) $("#var-min").value = lo;
  if (document.activeElement !== $("#var-max")) $("#var-max").value = hi;
  $("#term-select").replaceChildren(...blk.terms.map((t, i) => el("option", { value: i, selected: i === term }, t.name)));
  if (document.activeElement !== $("#term-name")) $("#term-name").value = blk.terms[term] ? blk.terms[term].name : "";
  const isOut = !isInput(current);
  $("#out-options").hidden = !isOut;
  if (isOut) {
    $("#out-method").value = blk.method || "COG";
    const d = blk.default;
    if (document.activeElement !== $("#out-default")) $("#out-default").value = !d ? "" : d.no_change && d.value === null ? "NC" : d.value === null ? "" : String(d.value);
  }
  renderChart();
  renderTable();
  fillDiagnostics($("#var-diags"), [...diagnosticsFor(`var:${current}`), ...diagnosticsFor(`term:${current}`)]);
}

// --- renaming and rules ------------------------------------------------------------

function eachCondition(cond, fn) {
  if (!cond) return;
  if (cond.type === "is" || cond.type === "degree") fn(cond);
  else if (cond.type === "not") eachCondition(cond.operand, fn);
  else cond.operands.forEach((c) => eachCondition(c, fn));
}

function renameVariable(oldName, newName) {
  const b = fb();
  for (const v of b.variables) if (v.name === oldName) v.name = newName;
  for (const blk of [...b.fuzzify, ...b.defuzzify]) if (blk.variable === oldName) blk.variable = newName;
  for (const rb of b.rule_blocks) {
    for (const r of rb.rules) {
      eachCondition(r.condition, (c) => c.variable === oldName && (c.variable = newName));
      for (const c of r.conclusions) if (c.variable === oldName) c.variable = newName;
    }
  }
  const s = state.settings;
  if (s.ranges && s.ranges[oldName]) {
    s.ranges[newName] = s.ranges[oldName];
    delete s.ranges[oldName];
  }
  if (s.recorder) {
    s.recorder.curves = (s.recorder.curves || []).map((c) => (c === oldName ? newName : c));
    if (s.recorder.signals && s.recorder.signals[oldName]) {
      s.recorder.signals[newName] = s.recorder.signals[oldName];
      delete s.recorder.signals[oldName];
    }
  }
}

function renameTerm(variable, oldName, newName) {
  const b = fb();
  for (const rb of b.rule_blocks) {
    for (const r of rb.rules) {
      eachCondition(r.condition, (c) => c.variable === variable && c.term === oldName && (c.term = newName));
      for (const c of r.conclusions) if (c.variable === variable && c.term === oldName) c.term = newName;
    }
  }
}

/** Remove references to terms of ``variable`` that no longer exist (the table cells
 * become blank, as in the manual); returns how many rules changed. */
function blankMissingTerms(variable) {
  const b = fb();
  const names = new Set(termBlock(variable).terms.map((t) => t.name));
  let count = 0;
  const keep = (c) => !(c.type === "is" && c.variable === variable && !names.has(c.term));
  const prune = (cond) => {
    if (!cond) return cond;
    if (cond.type === "is" || cond.type === "degree") return keep(cond) ? cond : null;
    if (cond.type === "not") {
      const inner = prune(cond.operand);
      return inner ? { ...cond, operand: inner } : null;
    }
    const ops = cond.operands.map(prune).filter(Boolean);
    if (!ops.length) return null;
    return ops.length === 1 ? ops[0] : { ...cond, operands: ops };
  };
  for (const rb of b.rule_blocks) {
    rb.rules = rb.rules.map((r) => {
      const condition = prune(r.condition);
      const conclusions = r.conclusions.filter((c) => !(c.variable === variable && c.term !== null && !names.has(c.term)));
      if (JSON.stringify(condition) !== JSON.stringify(r.condition) || conclusions.length !== r.conclusions.length) count++;
      return { ...r, condition, conclusions };
    });
    rb.rules = rb.rules.filter((r) => r.condition && r.conclusions.length);
  }
  return count;
}

// --- actions -------------------------------------------------------------------------

async function setRange() {
  const lo = parseFloat($("#var-min").value);
  const hi = parseFloat($("#var-max").value);
  if (!(Number.isFinite(lo) && Number.isFinite(hi) && lo < hi)) return status("the minimum must be below the maximum", "error");
  const [oldLo, oldHi] = range(current);
  const blk = termBlock(current);
  const xs = blk.terms.flatMap((t) => (handles(t) || []).map((p) => p.x));
  let adjust = false;
  if (xs.some((x) => x < lo || x > hi)) {
    const answer = await confirmDialog("Change the value range", "There are some points outside the selected range. Adjust all membership functions?", [["cancel", "Cancel"], ["ok", "OK"]]);
    if (answer !== "ok") return render();
    adjust = true;
  } else if (lo < oldLo || hi > oldHi) {
    const answer = await confirmDialog("Change the value range", "Should the membership functions be adjusted to the new range of values?", [["no", "No"], ["yes", "Yes"]]);
    adjust = answer === "yes";
  }
  if (adjust) {
    const scale = (x) => Math.round((lo + ((x - oldLo) * (hi - lo)) / (oldHi - oldLo)) * 1e6) / 1e6;
    for (const t of blk.terms) for (const p of handles(t) || []) p.set(scale(p.x));
  }
  if (blk.range) blk.range = { low: lo, high: hi };
  else state.settings.ranges = { ...(state.settings.ranges || {}), [current]: [lo, hi] };
  // the new range shows at once; the check confirms it
  if (state.report) state.report.ranges = { ...state.report.ranges, [current]: [lo, hi] };
  changed("range");
  status(`${current}: range ${lo} … ${hi}${adjust ? ", membership functions adjusted" : ""}`);
}

function insertTerm() {
  const blk = termBlock(current);
  const [lo, hi] = range(current);
  const names = blk.terms.map((t) => t.name);
  let k = blk.terms.length + 1;
  while (names.includes(`MBF_${k}`)) k++;
  const mid = (lo + hi) / 2;
  const w = (hi - lo) / 8;
  const r6 = (v) => Math.round(v * 1e6) / 1e6;
  const mf = isInput(current)
    ? { type: "points", points: [{ x: r6(mid - w), y: 0 }, { x: r6(mid), y: 1 }, { x: r6(mid + w), y: 0 }] }
    : { type: "singleton", value: r6(mid) };
  blk.terms.push({ name: `MBF_${k}`, mf });
  term = blk.terms.length - 1;
  point = 0;
  changed("terms");
}

async function deleteTerm() {
  const blk = termBlock(current);
  if (!blk.terms[term]) return;
  const name = blk.terms[term].name;
  blk.terms.splice(term, 1);
  term = Math.max(0, term - 1);
  const n = blankMissingTerms(current);
  changed("terms");
  status(`deleted term ${name}${n ? `; ${n} rule(s) lost it` : ""}`);
}

async function insertN() {
  const input = el("input", { type: "number", min: 1, max: 7, value: 5, id: "insert-n" });
  const answer = await confirmDialog("Insert membership functions", el("label", {}, "Number of membership functions (at most 7) ", input), [["cancel", "Cancel"], ["ok", "OK"]]);
  if (answer !== "ok") return;
  const n = Math.max(1, Math.min(7, parseInt(input.value, 10) || 5));
  const blk = termBlock(current);
  const [lo, hi] = range(current);
  const out = !isInput(current);
  blk.terms = evenTerms(n, lo, hi, out, termNames(n, out));
  term = 0;
  point = 0;
  const lost = blankMissingTerms(current);
  changed("terms");
  status(`${n} terms spread over ${lo} … ${hi}${lost ? `; ${lost} rule(s) referred to the old terms` : ""}`);
}

// --- dragging ------------------------------------------------------------------------

function axes() {
  const layout = chart()._fullLayout;
  return layout ? { xa: layout.xaxis, ya: layout.yaxis } : null;
}

function nearestHandle(event) {
  const ax = axes();
  if (!ax) return null;
  const rect = chart().getBoundingClientRect();
  const px = event.clientX - rect.left;
  const py = event.clientY - rect.top;
  const blk = termBlock(current);
  let best = null;
  blk.terms.forEach((t, i) => {
    (handles(t) || []).forEach((p, k) => {
      const hx = ax.xa.l2p(p.x) + ax.xa._offset;
      const dx = Math.abs(hx - px);
      // a singleton is a line: grab it anywhere along its height
      const hy = ax.ya.l2p(p.singleton ? Math.min(1, Math.max(0, ax.ya.p2l(py - ax.ya._offset))) : p.y) + ax.ya._offset;
      const d = Math.hypot(dx, hy - py) + (i === term ? 0 : 3); // prefer the selected term
      if (d < 14 && (!best || d < best.d)) best = { i, k, d };
    });
  });
  return best;
}

function onDown(event) {
  if (event.button !== 0 || !current) return;
  const hit = nearestHandle(event);
  if (!hit) return;
  event.preventDefault();
  term = hit.i;
  point = hit.k;
  dragging = { pointerId: event.pointerId };
  chart().setPointerCapture?.(event.pointerId);
  render();
}

function onMove(event) {
  if (!dragging) return;
  const ax = axes();
  const rect = chart().getBoundingClientRect();
  let x = ax.xa.p2l(event.clientX - rect.left - ax.xa._offset);
  const [lo, hi] = viewRange();
  x = Math.min(hi, Math.max(lo, x));
  const digits = Math.max(0, 3 - Math.floor(Math.log10(Math.max(1e-9, hi - lo))));
  x = Number(x.toFixed(Math.min(8, digits)));
  const { t } = selected();
  handles(t)[point].set(x);
  renderChart();
  renderTable();
  changed("points", { quiet: true });
}

function onUp() {
  if (!dragging) return;
  dragging = null;
  changed("points");
}

function onKey(event) {
  const { t } = selected();
  const h = t ? handles(t) : null;
  if (!h) return;
  const [lo, hi] = viewRange();
  const step = (hi - lo) / (event.shiftKey ? 1000 : 100);
  if (event.key === "ArrowLeft" || event.key === "ArrowRight") {
    event.preventDefault();
    const x = h[point].x + (event.key === "ArrowRight" ? step : -step);
    h[point].set(Number(x.toPrecision(10)));
    changed("points");
  } else if (event.key === "ArrowUp" || event.key === "ArrowDown") {
    event.preventDefault();
    point = (point + (event.key === "ArrowUp" ? 1 : h.length - 1)) % h.length;
    render();
  } else if (event.key === "+" || event.key === "-") {
    zoom = Math.max(0, Math.min(5, zoom + (event.key === "+" ? 1 : -1)));
    render();
  }
}

export function init() {
  on("model", () => !$("#view-variable").hidden && !dragging && render());
  on("report", () => !$("#view-variable").hidden && !dragging && render());
  on("loaded", () => {
    current = null;
    term = 0;
    point = 0;
    zoom = 0;
  });
  $("#var-select").addEventListener("change", (e) => {
    current = e.target.value;
    term = 0;
    point = 0;
    zoom = 0;
    render();
  });
  $("#var-name").addEventListener("change", (e) => {
    const name = e.target.value.trim();
    if (name === current) return;
    const refuse = (message) => ((e.target.value = current), status(message, "error"), render());
    if (!isIdentifier(name)) return refuse(`${name}: a name is a letter or _ followed by letters, digits or _`);
    if (variableNames().includes(name)) return refuse(`${name} exists already`);
    renameVariable(current, name);
    current = name;
    changed("rename");
    const warn = nameWarning("variable", name);
    if (warn) status(warn, "warning");
  });
  $("#term-select").addEventListener("change", (e) => {
    term = +e.target.value;
    point = 0;
    render();
  });
  $("#term-name").addEventListener("change", (e) => {
    const blk = termBlock(current);
    const name = e.target.value.trim();
    const old = blk.terms[term].name;
    if (name === old) return;
    const refuse = (message) => ((e.target.value = old), status(message, "error"), render());
    if (!isIdentifier(name)) return refuse(`${name}: not a valid term name`);
    if (blk.terms.some((t) => t.name === name)) return refuse(`${current} has a term ${name} already`);
    blk.terms[term].name = name;
    renameTerm(current, old, name);
    changed("rename");
    const warn = nameWarning("term", name);
    if (warn) status(warn, "warning");
  });
  $("#var-range-apply").addEventListener("click", setRange);
  $("#term-insert").addEventListener("click", insertTerm);
  $("#term-delete").addEventListener("click", deleteTerm);
  $("#term-insert-n").addEventListener("click", insertN);
  $("#zoom-in").addEventListener("click", () => ((zoom = Math.min(5, zoom + 1)), render()));
  $("#zoom-out").addEventListener("click", () => ((zoom = Math.max(0, zoom - 1)), render()));
  $("#zoom-reset").addEventListener("click", () => ((zoom = 0), render()));
  $("#out-method").addEventListener("change", (e) => {
    termBlock(current).method = e.target.value;
    changed("method");
  });
  $("#out-default").addEventListener("change", (e) => {
    const raw = e.target.value.trim();
    const blk = termBlock(current);
    if (!raw) blk.default = null;
    else if (raw.toUpperCase() === "NC") blk.default = { value: null, no_change: true };
    else if (Number.isFinite(parseFloat(raw))) blk.default = { value: parseFloat(raw), no_change: false };
    else return status("DEFAULT is a number or NC", "error");
    changed("default");
  });
  const node = chart();
  node.addEventListener("pointerdown", onDown, true);
  node.addEventListener("pointermove", onMove);
  node.addEventListener("pointerup", onUp);
  node.addEventListener("pointercancel", onUp);
  node.addEventListener("keydown", onKey);
}

export function shown() {
  render();
}

export function focus(target) {
  if (target.name) current = target.name;
  const blk = termBlock(current);
  if (target.term && blk) term = Math.max(0, blk.terms.findIndex((t) => t.name === target.term));
  point = 0;
  render();
}
