// The name limits of the S7 configuration tool (manual 6.2 "Define Project": a project name
// of at most 8 characters; 6.4: inputs and outputs up to 10, terms up to 7, letters, digits
// and "_", not starting with a digit; 1.3: only that many characters are significant in FPL).
// The numbers are the siemens profile's (LIMITS in blocks/siemens/profile.py, sent by
// /api/info); the Define Project dialog takes at most 8 characters, as the manual's, and
// the name fields accept longer names (IEC FCL has no limit) with a warning.
import { state, on } from "./state.js";
import { $ } from "./ui.js";

const FALLBACK = { project_name: 8, variable_name: 10, term_name: 7 };

export function limits() {
  return (state.info && state.info.siemens_limits) || FALLBACK;
}

/** A warning for ``name`` of a ``kind`` ("variable" or "term") the S7 tool would not
 * take, or null. */
export function nameWarning(kind, name) {
  const n = kind === "term" ? limits().term_name : limits().variable_name;
  if (name.length <= n) return null;
  const section = kind === "term" ? "6.4: terms" : "6.4: inputs and outputs";
  return `${name}: ${name.length} characters; the S7 configuration tool takes ${n} (manual ${section}) and only the first ${n} (${name.slice(0, n)}) are significant in FPL (1.3)`;
}

on("ready", () => {
  const L = limits();
  const project = $("#new-name");
  project.maxLength = L.project_name;
  project.title = `at most ${L.project_name} characters (manual 6.2, Define Project)`;
  $("#var-name").title = `inputs and outputs: up to ${L.variable_name} characters in the S7 tool (manual 6.4)`;
  $("#term-name").title = `terms: up to ${L.term_name} characters in the S7 tool (manual 6.4)`;
});
