// The check panel for a MATLAB FIS file: its [System] settings and membership functions in
// the names MATLAB's Fuzzy Logic Designer uses (AndMethod 'min', trimf, centroid...), not
// the IEC 61131-7 conformance tables (those stay one click away).
import { el } from "./ui.js";

const AND = { MIN: "min", PROD: "prod", BDIF: "bounded difference", NIPMIN: "nilpotent min", EPROD: "Einstein product", HPROD: "Hamacher product", DPROD: "drastic product" };
const OR = { MAX: "max", ASUM: "probor", BSUM: "bounded sum", NSUM: "normalized sum", NIPMAX: "nilpotent max", ESUM: "Einstein sum", HSUM: "Hamacher sum", DSUM: "drastic sum" };
const IMP = { MIN: "min", PROD: "prod" };
const AGG = { MAX: "max", SUM: "sum", BSUM: "bounded sum", NSUM: "normalized sum", ASUM: "probor" };
const DEFUZZ = { COG: "centroid", COA: "bisector", MM: "mom", LM: "lom", RM: "som", COGS: "wtaver (singletons)" };
const TR = { KM: "karnikmendel", EKM: "ekm", IASC: "iasc", EIASC: "eiasc" };
const MF = { triangle: "trimf", trapezoid: "trapmf", gaussian: "gaussmf", gaussian2: "gauss2mf", bell: "gbellmf", sigmoid: "sigmf", dsigmoid: "dsigmf", psigmoid: "psigmf", zshape: "zmf", sshape: "smf", pishape: "pimf", linear: "linear", constant: "constant" };

function mfName(mf) {
  if (mf.type === "singleton") return "constant (singleton)";
  if (mf.type === "points") return "trapmf/trimf (points)";
  return MF[mf.kind] || mf.kind || mf.type;
}

function isSugeno(b) {
  return b.defuzzify.every((d) => d.terms.every((t) => t.mf.type === "singleton" || ["linear", "constant"].includes(t.mf.kind)));
}

/** The panel's content for function block ``b`` (the model's JSON) read from a FIS file. */
export function matlabSummary(b) {
  const rb = b.rule_blocks[0] || {};
  const d = b.defuzzify[0] || {};
  const rules = b.rule_blocks.reduce((n, r) => n + r.rules.length, 0);
  const ins = b.variables.filter((v) => v.kind === "VAR_INPUT").length;
  const outs = b.variables.filter((v) => v.kind === "VAR_OUTPUT").length;
  // an interval type-2 system (a term with a lower function): mamfistype2 / sugfistype2
  const type2 = [...b.fuzzify, ...b.defuzzify].some((f) => f.terms.some((t) => t.lower));
  const row = (k, v) => el("tr", {}, el("th", {}, k), el("td", { class: "mono" }, v));
  const table = el(
    "table",
    { class: "values matlab-system", id: "matlab-system" },
    el("caption", {}, "MATLAB FIS [System]"),
    el(
      "tbody",
      {},
      row("Type", `'${isSugeno(b) ? "sugeno" : "mamdani"}${type2 ? "type2" : ""}'`),
      row("NumInputs / NumOutputs", `${ins} / ${outs}`),
      row("NumRules", String(rules)),
      row("AndMethod", `'${AND[rb.and_op || "MIN"] || rb.and_op}'`),
      row("OrMethod", `'${OR[rb.or_op || "MAX"] || rb.or_op}'`),
      row("ImpMethod", `'${IMP[rb.act || "MIN"] || rb.act}'`),
      row("AggMethod", `'${AGG[d.accu || rb.accu || "MAX"] || d.accu || rb.accu}'`),
      row("DefuzzMethod", `'${DEFUZZ[d.method] || d.method}'`),
      ...(type2 ? [row("TypeReductionMethod", `'${TR[d.type_reduction || "KM"] || d.type_reduction}'`)] : []),
    ),
  );
  const used = new Map();
  for (const f of [...b.fuzzify, ...b.defuzzify]) for (const t of f.terms) used.set(mfName(t.mf), (used.get(mfName(t.mf)) || 0) + 1);
  const mfs = el("p", { class: "matlab-mfs" }, "Membership functions: ", [...used].map(([n, c]) => `${n} ×${c}`).join(", "));
  const note = el("p", { class: "hint" }, "Read from a MATLAB FIS file. Save writes it as IEC 61131-7 FCL (a project); Export writes FIS again.");
  return el("div", { class: "matlab" }, table, mfs, note);
}
