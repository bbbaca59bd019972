// Terms as the membership-function editor sees them: which parameters each kind has, which
// of them can be dragged on the chart and where their handle sits, and how to turn a term
// into another kind keeping its place.  All of it per kind comes from the server's catalogue
// (GET /api/shapes: the shape registry, fuzzyctl.kinds.shapes); no per-kind table and no
// membership formula lives here: curves come from the engine (the check report); handles
// are positions read from the parameters.

// kind -> {params, summary, variadic, family, roles, placement, handles, polygon, pickable}
export let SHAPES = {};

export function setShapes(shapes) {
  SHAPES = shapes;
}

const num = (v) => typeof v === "number" && Number.isFinite(v);

/** The kind of a term's membership function as the Shape picker lists it. */
export function kindOf(mf) {
  if (mf.type === "shape") return mf.kind;
  return mf.type; // points, singleton, singletons, function
}

export function kindLabel(kind) {
  const names = { points: "points (IEC)", singleton: "singleton", singletons: "singletons", function: "function (expression)" };
  return names[kind] || kind;
}

/** Every kind the picker offers, inputs first the fuzzy sets, outputs also the
 * Takagi-Sugeno ones. */
export function kinds(isOutput) {
  // not pickable: jFuzzyLogic's COSINE with a variable half-width (with numbers it is a
  // cosine, and FCL writes it as one); Takagi-Sugeno kinds on outputs only
  const shapeKinds = Object.keys(SHAPES).filter((k) => SHAPES[k].pickable && (isOutput || SHAPES[k].family !== "ts"));
  return ["points", "singleton", ...(isOutput ? ["singletons"] : []), ...shapeKinds, "function"];
}

// Handles of a parameter (the catalogue's ``handles``): a position (the parameter is an
// x), or a spread measured from a centre parameter (x = centre + factor * spread), at the
// height the shape has there.
const handleSpecs = (kind) => (SHAPES[kind] && SHAPES[kind].handles) || [];

/** The draggable handles of a term: ``[{x, y, set(x), line}]`` (``line``: a vertical line
 * grabbed anywhere along it, as singletons), or [] when nothing can be dragged (a term
 * given by an expression, parameters given by variables). */
export function handles(term) {
  const mf = term.mf;
  if (mf.type === "points") {
    if (!mf.points.every((p) => num(p.x) && num(p.y))) return [];
    return mf.points.map((p) => ({ x: p.x, y: p.y, set: (x) => (p.x = x) }));
  }
  if (mf.type === "singleton") return num(mf.value) ? [{ x: mf.value, y: 1, set: (x) => (mf.value = x), line: true }] : [];
  if (mf.type === "singletons") {
    if (!mf.points.every((p) => num(p.x) && num(p.y))) return [];
    return mf.points.map((p) => ({ x: p.x, y: p.y, set: (x) => (p.x = x), line: true }));
  }
  if (mf.type !== "shape" || !handleSpecs(mf.kind).length) return [];
  const h = num(mf.height) ? mf.height : 1;
  const out = [];
  for (const spec of handleSpecs(mf.kind)) {
    const p = mf.params;
    if (!num(p[spec.at]) || (spec.centre !== undefined && !num(p[spec.centre]))) continue;
    if (spec.centre === undefined) {
      out.push({ x: p[spec.at], y: spec.y * h, set: (x) => (p[spec.at] = x), line: !!spec.line });
    } else {
      const centre = p[spec.centre];
      const x = centre + spec.factor * Math.abs(p[spec.at]);
      out.push({
        x,
        y: spec.y * h,
        set: (v) => {
          const spread = (v - p[spec.centre]) / spec.factor;
          p[spec.at] = Math.max(Math.abs(spread), 1e-9) * (p[spec.at] < 0 ? -1 : 1);
        },
      });
    }
  }
  return out;
}

/** Where a term sits, read from its curve: support [a, b] and peak c. */
export function placeOf(curve, lo, hi) {
  if (curve && curve.singleton !== undefined) return { a: curve.singleton, b: curve.singleton, c: curve.singleton };
  if (curve && curve.spikes && curve.spikes.length) {
    const xs = curve.spikes.map((p) => p[0]);
    return { a: Math.min(...xs), b: Math.max(...xs), c: xs[0] };
  }
  const pts = (curve && curve.points) || [];
  const on = pts.filter((p) => p[1] > 1e-6);
  if (!on.length) return { a: lo, b: hi, c: (lo + hi) / 2 };
  const top = Math.max(...on.map((p) => p[1]));
  const peak = on.filter((p) => p[1] >= top - 1e-9).map((p) => p[0]);
  let a = Math.max(lo, Math.min(...on.map((p) => p[0])));
  let b = Math.min(hi, Math.max(...on.map((p) => p[0])));
  const c = (Math.min(...peak) + Math.max(...peak)) / 2;
  if (b - a < (hi - lo) / 100) {
    a = Math.max(lo, c - (hi - lo) / 8);
    b = Math.min(hi, c + (hi - lo) / 8);
  }
  return { a, b, c: Math.max(a, Math.min(b, c)) };
}

const r6 = (v) => Math.round(v * 1e6) / 1e6;

/** A membership function of ``kind`` placed where ``place`` says (support and peak). */
export function convert(kind, place, nInputs = 1) {
  const { a, b, c } = place;
  const w = Math.max(b - a, 1e-9);
  const shape = (params) => ({ type: "shape", kind, params: params.map(r6), height: 1 });
  switch (kind) {
    case "points":
      return { type: "points", points: [{ x: r6(a), y: 0 }, { x: r6(c), y: 1 }, { x: r6(b), y: 0 }] };
    case "singleton":
      return { type: "singleton", value: r6(c) };
    case "singletons":
      return { type: "singletons", points: [{ x: r6(c), y: 1 }] };
    case "function":
      return null; // written in the FCL field
  }
  const spec = SHAPES[kind];
  if (!spec) return null;
  // a variadic shape (Takagi-Sugeno linear): one zero per input and the constant
  if (spec.variadic) return shape(new Array(nInputs + 1).fill(0));
  return shape(spec.placement.map((t) => evalPlacement(t, { a, b, c, w })));
}

/** A placement expression of the catalogue: a number, a name or [op, left, right]. */
function evalPlacement(t, env) {
  if (typeof t === "number") return t;
  if (typeof t === "string") return env[t];
  const [op, l, r] = t;
  if (op === "neg") return -evalPlacement(l, env);
  const x = evalPlacement(l, env);
  const y = evalPlacement(r, env);
  return op === "+" ? x + y : op === "-" ? x - y : op === "*" ? x * y : x / y;
}

/** The name of parameter ``i`` of a shape kind. */
export function paramName(kind, i) {
  const spec = SHAPES[kind];
  if (!spec) return `p${i + 1}`;
  if (spec.variadic) return `${spec.params[0]} ${i + 1}`;
  return spec.params[i] || `p${i + 1}`;
}

/** A parameter as typed: a number, or the name of a variable (a reference). */
export function readParam(text) {
  const t = text.trim();
  if (t === "") return undefined;
  const v = Number(t);
  if (Number.isFinite(v)) return v;
  if (/^[A-Za-z_][A-Za-z0-9_]*$/.test(t)) return { type: "ref", name: t };
  return undefined;
}

export function paramText(p) {
  return p && typeof p === "object" ? p.name : String(p);
}

// What each parameter is, for rescaling a term to a new range (the catalogue's ``roles``):
// x a position, width a width, slope a slope (per unit of x), number/coef a pure number.
const roleOf = (kind, i) => (SHAPES[kind] && SHAPES[kind].roles ? SHAPES[kind].roles[i] : undefined);

/** The positions (x values) of a term with numeric parameters. */
export function positions(mf) {
  if (mf.type === "points" || mf.type === "singletons") return mf.points.map((p) => p.x).filter(num);
  if (mf.type === "singleton") return num(mf.value) ? [mf.value] : [];
  if (mf.type === "shape") return mf.params.filter((p, i) => roleOf(mf.kind, i) === "x" && num(p));
  return [];
}

/** Map a term onto a new range: positions through ``f``, widths times ``k``, slopes
 * divided by ``k`` (``f(x) = lo + (x - oldLo) * k``). */
export function rescale(mf, f, k) {
  const round = (v) => Math.round(v * 1e6) / 1e6;
  if (mf.type === "points" || mf.type === "singletons") for (const p of mf.points) if (num(p.x)) p.x = round(f(p.x));
  if (mf.type === "singleton" && num(mf.value)) mf.value = round(f(mf.value));
  if (mf.type === "shape" && SHAPES[mf.kind]) {
    mf.params = mf.params.map((p, i) => {
      if (!num(p)) return p;
      const role = roleOf(mf.kind, i);
      return role === "x" ? round(f(p)) : role === "width" ? round(p * k) : role === "slope" ? p / k : p;
    });
  }
}

/** Points to draw for a term from the local model (live while dragging), extended flat to
 * the range ends as IEC defines; null: draw the server's curve. */
export function localCurve(term, lo, hi) {
  const mf = term.mf;
  const h = handles(term);
  if (!h.length) return null;
  if (mf.type === "singleton") return { singleton: h[0].x };
  if (mf.type === "singletons") return { spikes: mf.points.map((p) => [p.x, p.y]) };
  if (mf.type === "points") {
    const pts = mf.points.map((p) => [p.x, p.y]).sort((a, b) => a[0] - b[0]);
    return { points: [[Math.min(lo, pts[0][0]), pts[0][1]], ...pts, [Math.max(hi, pts[pts.length - 1][0]), pts[pts.length - 1][1]]] };
  }
  if (mf.type === "shape" && SHAPES[mf.kind] && SHAPES[mf.kind].polygon && num(mf.height)) {
    const pts = h.map((p) => [p.x, p.y]).sort((a, b) => a[0] - b[0]);
    return { points: [[Math.min(lo, pts[0][0]), 0], ...pts, [Math.max(hi, pts[pts.length - 1][0]), 0]] };
  }
  return null;
}
