// Requests to the studio's backend.  Errors become exceptions carrying the server's
// detail (a message, or pydantic's list of problems) and its diagnostics.

export class ApiError extends Error {
  constructor(status, payload) {
    super(ApiError.describe(payload) || `request failed (${status})`);
    this.status = status;
    this.payload = payload || {};
  }
  static describe(payload) {
    if (!payload) return "";
    const d = payload.detail;
    if (typeof d === "string") return d;
    if (Array.isArray(d)) return d.map((e) => `${(e.loc || []).join(".")}: ${e.msg}`).join("; ");
    return "";
  }
}

// The busy indicator: a bar under the menu bar (and the "busy" mark on <body>) while a
// request has been under way for more than 150 ms; background polling does not count.
let pending = 0;
let shown = null;
function busy(delta, quiet) {
  if (quiet) return;
  pending += delta;
  const bar = document.getElementById("busy");
  if (pending > 0 && shown === null) {
    shown = setTimeout(() => {
      document.body.dataset.busy = "true";
      if (bar) bar.hidden = false;
    }, 150);
  } else if (pending === 0) {
    clearTimeout(shown);
    shown = null;
    document.body.dataset.busy = "false";
    if (bar) bar.hidden = true;
  }
}

async function request(method, path, body, { quiet = false } = {}) {
  const init = { method, headers: { Accept: "application/json" } };
  if (body !== undefined) {
    init.headers["Content-Type"] = "application/json";
    init.body = JSON.stringify(body);
  }
  busy(1, quiet);
  let response;
  let payload = null;
  try {
    response = await fetch(path, init);
    try {
      payload = await response.json();
    } catch (_) {
      payload = null;
    }
  } finally {
    busy(-1, quiet);
  }
  if (!response.ok) throw new ApiError(response.status, payload);
  return payload;
}

export const get = (path, options) => request("GET", path, undefined, options);
export const post = (path, body, options) => request("POST", path, body, options);
export const del = (path) => request("DELETE", path, {});
