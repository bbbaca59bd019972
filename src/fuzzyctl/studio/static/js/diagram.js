// Project view (manual 6.2, 6.3): the function block as a block diagram - inputs, rule
// blocks, outputs; a click (or Enter) opens the editor of that part.
import { state, on, emit, fb, inputs, outputs, diagnosticsFor, changed, termNames, evenTerms, range, status } from "./state.js";
import { $ } from "./ui.js";

const NS = "http://www.w3.org/2000/svg";
function svg(tag, attrs = {}, text = null) {
  const node = document.createElementNS(NS, tag);
  for (const [k, v] of Object.entries(attrs)) node.setAttribute(k, v);
  if (text !== null) node.textContent = text;
  return node;
}

function box(parent, x, y, w, h, label, sub, kind, id, onOpen) {
  const g = svg("g", { class: `node ${kind}`, tabindex: "0", role: "button", "aria-label": `${kind} ${label}`, "data-id": id });
  g.append(svg("rect", { x, y, width: w, height: h, rx: 6 }));
  g.append(svg("text", { x: x + w / 2, y: y + h / 2 - (sub ? 4 : -4), "text-anchor": "middle", class: "label" }, label));
  if (sub) g.append(svg("text", { x: x + w / 2, y: y + h / 2 + 13, "text-anchor": "middle", class: "sub" }, sub));
  // a variable's box also carries the diagnostics of its terms
  const diags = id.startsWith("var:") ? [...diagnosticsFor(id), ...diagnosticsFor(`term:${id.slice(4)}`)] : diagnosticsFor(id);
  if (diags.length) {
    const bad = diags.some((d) => d.severity === "error");
    g.append(svg("circle", { cx: x + w - 4, cy: y + 4, r: 9, class: bad ? "mark error" : "mark warning" }));
    g.append(svg("text", { x: x + w - 4, y: y + 8, "text-anchor": "middle", class: "mark-text" }, String(diags.length)));
    g.append(svg("title", {}, diags.map((d) => `${d.severity}: ${d.message}`).join("\n")));
  }
  g.addEventListener("click", onOpen);
  g.addEventListener("keydown", (e) => (e.key === "Enter" || e.key === " ") && (e.preventDefault(), onOpen()));
  parent.append(g);
}

function render() {
  const host = $("#diagram");
  host.replaceChildren();
  const b = fb();
  if (!b) {
    host.textContent = "No project: New (Alt+N) or Open (Ctrl+O).";
    return;
  }
  const ins = inputs();
  const outs = outputs();
  const blocks = b.rule_blocks.length ? b.rule_blocks : [{ name: "(no rule block)", rules: [] }];
  const rows = Math.max(ins.length, outs.length, blocks.length, 1);
  const W = 760;
  const H = Math.max(200, rows * 70 + 60);
  const root = svg("svg", { viewBox: `0 0 ${W} ${H}`, width: W, height: H, role: "group", "aria-label": `function block ${b.name}` });
  root.append(svg("rect", { x: 150, y: 10, width: 460, height: H - 20, rx: 10, class: "fb" }));
  root.append(svg("text", { x: 380, y: 30, "text-anchor": "middle", class: "fb-name" }, `FUNCTION_BLOCK ${b.name || ""}`));
  const ruleY = (i) => 50 + ((H - 80) / blocks.length) * (i + 0.5) - 30;
  blocks.forEach((rb, i) => {
    const y = ruleY(i);
    const midY = y + 30;
    ins.forEach((v, k) => root.append(svg("line", { x1: 130, y1: 50 + k * 70 + 25, x2: 300, y2: midY, class: "wire" })));
    outs.forEach((v, k) => root.append(svg("line", { x1: 460, y1: midY, x2: 630, y2: 50 + k * 70 + 25, class: "wire" })));
    box(root, 300, y, 160, 60, "If … Then", `${rb.name || "rules"}: ${rb.rules.length} rule(s)`, "rules", `ruleblock:${i}`, () => emit("show", { view: "rules", target: { block: i, rule: null } }));
  });
  ins.forEach((v, k) => {
    const blk = b.fuzzify.find((f) => f.variable === v.name);
    const [lo, hi] = range(v.name);
    box(root, 10, 50 + k * 70, 120, 50, v.name, `${blk ? blk.terms.length : 0} terms, ${lo}…${hi}`, "input", `var:${v.name}`, () => emit("show", { view: "variable", target: { name: v.name } }));
  });
  outs.forEach((v, k) => {
    const blk = b.defuzzify.find((d) => d.variable === v.name);
    box(root, 630, 50 + k * 70, 120, 50, v.name, `${blk ? blk.terms.length : 0} terms, ${blk && blk.method ? blk.method : "COG"}`, "output", `var:${v.name}`, () => emit("show", { view: "variable", target: { name: v.name } }));
  });
  host.append(root);
}

function uniqueName(prefix) {
  const names = new Set(fb().variables.map((v) => v.name));
  let i = 1;
  while (names.has(`${prefix}${i}`)) i++;
  return `${prefix}${i}`;
}

function addVariable(isOutput) {
  const b = fb();
  if (!b) return;
  const name = uniqueName(isOutput ? "output" : "input");
  const kind = isOutput ? "VAR_OUTPUT" : "VAR_INPUT";
  // inserted at the end of its kind, as the manual's Edit menu does
  let at = b.variables.length;
  for (let i = b.variables.length - 1; i >= 0; i--) if (b.variables[i].kind === kind) { at = i + 1; break; }
  b.variables.splice(at, 0, { name, kind, data_type: "REAL", initial: null, range: null });
  const terms = evenTerms(5, -100, 100, isOutput, termNames(5, isOutput));
  if (isOutput) b.defuzzify.push({ variable: name, terms, range: null, method: "COGS", default: { value: null, no_change: true }, accu: null, clamp: false });
  else b.fuzzify.push({ variable: name, terms, range: null, clamp: false });
  state.settings.ranges = { ...(state.settings.ranges || {}), [name]: [-100, 100] };
  changed("structure");
  status(`added ${name}`);
}

function deleteLast(isOutput) {
  const b = fb();
  const list = isOutput ? outputs() : inputs();
  if (!b || list.length <= 1) return status("a function block keeps at least one input and one output", "error");
  const name = list[list.length - 1].name;
  b.variables = b.variables.filter((v) => v.name !== name);
  b.fuzzify = b.fuzzify.filter((f) => f.variable !== name);
  b.defuzzify = b.defuzzify.filter((d) => d.variable !== name);
  // the variable's parts leave every rule; a rule left without a conclusion goes
  for (const rb of b.rule_blocks) {
    rb.rules = rb.rules
      .map((r) => ({ ...r, condition: dropVariable(r.condition, name), conclusions: r.conclusions.filter((c) => c.variable !== name) }))
      .filter((r) => r.conclusions.length && r.condition);
  }
  if (state.settings.ranges) delete state.settings.ranges[name];
  changed("structure");
  status(`deleted ${name} (and its parts of the rules)`);
}

function dropVariable(cond, name) {
  if (!cond) return cond;
  if (cond.type === "is" || cond.type === "degree") return cond.variable === name ? null : cond;
  if (cond.type === "not") {
    const inner = dropVariable(cond.operand, name);
    return inner ? { ...cond, operand: inner } : null;
  }
  const ops = cond.operands.map((c) => dropVariable(c, name)).filter(Boolean);
  if (!ops.length) return null;
  return ops.length === 1 ? ops[0] : { ...cond, operands: ops };
}

export function init() {
  on("model", render);
  on("report", render);
  $("#btn-add-input").addEventListener("click", () => addVariable(false));
  $("#btn-add-output").addEventListener("click", () => addVariable(true));
  $("#btn-del-input").addEventListener("click", () => deleteLast(false));
  $("#btn-del-output").addEventListener("click", () => deleteLast(true));
}
export function shown() {
  render();
}
