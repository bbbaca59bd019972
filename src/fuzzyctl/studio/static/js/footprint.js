// Interval type-2 terms in the variable editor (docs/type2.md, "Studio"): the footprint of
// uncertainty drawn as the area between the upper curve and the lower one (the lower curve
// comes from the engine, in the check report), and the lower function edited - MATLAB's
// scale and lag (one lag, or left and right), or an explicit function with its own
// parameters.  lower <= upper is checked by the server; its message is shown here.
import { post } from "./api.js";
import { el, fillDiagnostics } from "./ui.js";
import { SHAPES, paramName, readParam, paramText } from "./terms.js";

const num = (v) => typeof v === "number" && Number.isFinite(v);

function fill(color) {
  const n = parseInt(color.slice(1), 16);
  return `rgba(${(n >> 16) & 255},${(n >> 8) & 255},${n & 255},0.2)`;
}

/** Plotly traces of a term's footprint: the area between ``upper`` points and the
 * server's lower curve, and the lower curve dashed; [] for a type-1 term. */
export function footprintTraces(name, upper, lower, color, active) {
  if (!lower || !upper || !upper.length) return [];
  const xs = [...upper.map((p) => p[0]), ...lower.map((p) => p[0]).reverse()];
  const ys = [...upper.map((p) => p[1]), ...lower.map((p) => p[1]).reverse()];
  return [
    { x: xs, y: ys, mode: "lines", fill: "toself", fillcolor: fill(color), line: { width: 0 }, hoverinfo: "skip", name: `${name} footprint` },
    { x: lower.map((p) => p[0]), y: lower.map((p) => p[1]), mode: "lines", line: { color, width: active ? 2.5 : 1.2, dash: "dash" }, name: `${name} lower` },
  ];
}

/** The lower function a term gets when the user turns it into a type-2 term. */
function initialLower(kind, t) {
  if (kind === "scale_lag") return { type: "lower", mf: null, scale: 1, lag: [0.2] }; // MATLAB's defaults
  // an explicit lower: the upper at half its height (below it by construction)
  const mf = JSON.parse(JSON.stringify(t.mf));
  if (mf.type === "shape") mf.height = num(mf.height) ? mf.height / 2 : 0.5;
  else if (mf.type === "points") for (const p of mf.points) if (num(p.y)) p.y /= 2;
  return { type: "lower", mf, scale: 1, lag: [0] };
}

function field(label, id, value, onChange, title = "") {
  const input = el("input", { id, value, spellcheck: "false", "aria-label": label, title });
  input.addEventListener("change", () => onChange(input.value, input));
  input.addEventListener("keydown", (e) => e.key === "Enter" && (e.preventDefault(), input.dispatchEvent(new Event("change"))));
  return [el("label", { for: id }, label), input];
}

/** Fill the lower-function panel for term ``t`` of ``variable``.  ``ctx``: {changed(),
 * status(message, kind), body(extra), diagnostics: the check's diagnostics of this term}. */
export function renderLower(t, variable, ctx) {
  const box = document.getElementById("term-lower");
  const kindSelect = document.getElementById("lower-kind");
  const params = document.getElementById("lower-params");
  const lower = t.lower || null;
  const kind = !lower ? "none" : lower.mf ? "mf" : "scale_lag";
  kindSelect.value = kind;
  if (lower) box.open = true;
  params.replaceChildren();
  kindSelect.onchange = () => {
    const next = kindSelect.value;
    t.lower = next === "none" ? null : initialLower(next, t);
    if (!t.lower) delete t.lower;
    ctx.changed();
  };
  const bad = (input, message) => {
    input.classList.add("bad");
    ctx.status(message, "error");
  };
  if (kind === "scale_lag") {
    const set = (apply) => (value, input) => {
      const v = value.trim() === "" ? null : Number(value);
      const why = apply(v);
      if (why) return bad(input, why);
      input.classList.remove("bad");
      ctx.changed();
    };
    const lag = lower.lag || [0];
    params.append(
      ...field("scale", "lower-scale", String(lower.scale), set((v) => (num(v) && v > 0 && v <= 1 ? ((lower.scale = v), null) : "LowerScale is in (0, 1]")), "the lower function's height: scale × the upper's"),
      ...field("lag (left)", "lower-lag-left", String(lag[0]), set((v) => (num(v) && v >= 0 && v < 1 ? ((lower.lag = lag.length > 1 ? [v, lag[1]] : [v]), null) : "LowerLag is in [0, 1)")), "the lower function starts where the upper reaches this degree"),
      ...field("lag (right)", "lower-lag-right", lag.length > 1 ? String(lag[1]) : "", set((v) => (v === null ? ((lower.lag = [lag[0]]), null) : num(v) && v >= 0 && v < 1 ? ((lower.lag = [lag[0], v]), null) : "LowerLag is in [0, 1)")), "the falling side's lag; empty: the same as the left"),
    );
  } else if (kind === "mf") {
    const mf = lower.mf;
    if (mf.type === "shape") {
      const values = [...mf.params, mf.height];
      values.forEach((p, i) => {
        const last = i === mf.params.length;
        params.append(
          ...field(last ? "height" : paramName(mf.kind, i), `lower-param-${last ? "height" : i}`, paramText(p), (v, input) => {
            const x = readParam(v);
            if (!num(x)) return bad(input, "a parameter of the lower function is a number");
            if (last) mf.height = x;
            else mf.params[i] = x;
            input.classList.remove("bad");
            ctx.changed();
          }, (SHAPES[mf.kind] || {}).summary || ""),
        );
      });
    } else if (mf.type === "points") {
      mf.points.forEach((p, k) => {
        params.append(
          ...field(`point ${k + 1}`, `lower-point-${k}`, `${paramText(p.x)} ${paramText(p.y)}`, (v, input) => {
            const [x, y] = v.trim().split(/[\s,;]+/).map(Number);
            if (!num(x) || !num(y) || y < 0 || y > 1) return bad(input, "a point of the lower function is x and a degree in [0, 1]");
            p.x = x;
            p.y = y;
            input.classList.remove("bad");
            ctx.changed();
          }, "x and degree"),
        );
      });
    }
    params.append(
      ...field("as FCL", "lower-fcl", "", async (v, input) => {
        if (!v.trim()) return;
        let result;
        try {
          result = await post("/api/term/parse", ctx.body({ variable, text: v }));
        } catch (err) {
          return bad(input, err.message);
        }
        if (!result.ok) return bad(input, result.diagnostics.map((d) => d.message).join("; ") || "not a membership function");
        lower.mf = result.mf;
        input.classList.remove("bad");
        ctx.changed();
      }, "the lower function in any spelling the FCL parser reads (TRIAN 2 5 8, (0, 0) (5, 0.8) (10, 0), ...), Enter applies"),
    );
  }
  fillDiagnostics(document.getElementById("lower-diags"), ctx.diagnostics.filter((d) => d.code === "type2-lower"));
}
