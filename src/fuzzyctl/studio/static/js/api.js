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

async function request(method, path, body) {
  const init = { method, headers: { Accept: "application/json" } };
  if (body !== undefined) {
    init.headers["Content-Type"] = "application/json";
    init.body = JSON.stringify(body);
  }
  const response = await fetch(path, init);
  let payload = null;
  try {
    payload = await response.json();
  } catch (_) {
    payload = null;
  }
  if (!response.ok) throw new ApiError(response.status, payload);
  return payload;
}

export const get = (path) => request("GET", path);
export const post = (path, body) => request("POST", path, body);
export const del = (path) => request("DELETE", path, {});
