// On line (manual 6.7, 6.8): connect to a running `fuzzyctl serve`, pick an instance,
// watch its values, START_STOP / MAN_AUTO / forcing, and download the edited knowledge
// base after a confirmation that shows the difference of the two FCL texts.  The
// connection state is always in the menu bar; every command is disabled while it cannot
// work, and says why.
import { state, on, body, fmt, status } from "./state.js";
import { post } from "./api.js";
import { $, el, confirmDialog } from "./ui.js";
import { diffLines } from "./diff.js";

export const online = { url: null, token: null, instance: null, detail: null, instances: [], state: "off", error: null };
let poller = null;

function creds() {
  return { url: online.url, token: online.token || null, instance: online.instance };
}

function setState(next, error = null) {
  online.state = next;
  online.error = error;
  renderConnection();
}

/** Why each command cannot run now (null: it can). */
export function reasons() {
  const out = {};
  const connected = online.state === "on" && online.instance;
  const base = online.state === "lost" ? `the connection to ${online.url} is lost (${online.error || "no answer"}): Connect again` : online.state === "on" && !online.instance ? "the runtime has no instance" : "not connected: give the runtime's URL and Connect";
  const info = online.instances.find((i) => i.name === online.instance) || {};
  for (const id of ["on-start", "on-stop", "on-auto", "on-manual", "on-force", "on-release", "on-download"]) {
    if (!connected) out[id] = base;
    else if (!online.token && id !== "on-download") out[id] = "commands need the token (the file the runtime names, api-token)";
    else if (!online.token) out[id] = "a download needs the token (the file the runtime names, api-token)";
    else out[id] = null;
  }
  if (connected && info.style && info.style !== "xfuz") {
    out["on-auto"] = out["on-auto"] || `MAN_AUTO is a parameter of XFUZ instances; ${online.instance} is a ${info.style} instance`;
    out["on-manual"] = out["on-manual"] || out["on-auto"];
  }
  if (connected && !out["on-download"] && state.report && state.report.ok === false) out["on-download"] = "the knowledge base has errors: fix them first (Check panel)";
  if (connected && !out["on-download"] && !state.doc) out["on-download"] = "no project";
  return out;
}

function renderConnection() {
  const badge = $("#online-badge");
  const line = $("#on-connection");
  const cls = online.state;
  badge.className = `badge conn ${cls}`;
  line.className = `conn-line ${cls}`;
  if (cls === "on") {
    const where = online.url.replace(/^https?:\/\//, "");
    badge.textContent = `● on line: ${online.instance || "?"} @ ${where}`;
    line.textContent = `Connected to ${online.url}${online.instance ? `, instance ${online.instance}` : ""}.`;
  } else if (cls === "lost") {
    badge.textContent = "● connection lost";
    line.textContent = `Connection to ${online.url} lost: ${online.error || "no answer"}. Connect again.`;
  } else {
    badge.textContent = "● off line";
    line.textContent = "Not connected: give the runtime's URL (fuzzyctl serve prints it) and the token, then Connect.";
  }
  $("#on-disconnect").disabled = cls === "off";
  const why = reasons();
  const messages = new Set();
  for (const [id, reason] of Object.entries(why)) {
    const button = $(`#${id}`);
    button.disabled = !!reason;
    button.title = reason || button.dataset.title || "";
    if (reason) messages.add(reason);
  }
  $("#on-reason").textContent = messages.size ? `Disabled: ${[...messages].join("; ")}.` : "";
  $("#on-force-input").disabled = !!why["on-force"];
  $("#on-force-value").disabled = !!why["on-force"];
}

async function connect() {
  online.url = $("#on-url").value.trim();
  online.token = $("#on-token").value.trim() || null;
  try {
    const res = await post("/api/online/instances", { url: online.url, token: online.token || null });
    online.instances = res.instances;
    const select = $("#on-instance");
    select.replaceChildren(...res.instances.map((i) => el("option", { value: i.name }, `${i.name} (${i.style}, ${i.state})`)));
    online.instance = res.instances.length ? res.instances[0].name : null;
    setState("on");
    status(`connected to ${res.api}: fuzzyctl ${res.health.version}, ${res.instances.length} instance(s)`);
    await read();
    startPolling();
  } catch (err) {
    setState(online.state === "on" ? "lost" : "off");
    status(err.message, "error");
  }
}

function disconnect() {
  stopPolling();
  online.detail = null;
  online.instances = [];
  online.instance = null;
  $("#on-instance").replaceChildren();
  $("#on-detail").replaceChildren();
  $("#on-values tbody").replaceChildren();
  setState("off");
  status("disconnected");
}

async function read({ quiet = false } = {}) {
  if (!online.url || !online.instance) return;
  try {
    online.detail = await post("/api/online/read", creds(), { quiet });
    if (online.state !== "on") setState("on");
    render();
  } catch (err) {
    setState("lost", err.message);
    if (!quiet) status(err.message, "error");
  }
}

function startPolling() {
  stopPolling();
  // the values while the On line view shows, a heartbeat for the menu bar otherwise
  let tick = 0;
  poller = setInterval(() => {
    tick++;
    if (!$("#view-online").hidden) read({ quiet: true });
    else if (tick % 4 === 0 && online.state !== "off") read({ quiet: true });
  }, 500);
}
function stopPolling() {
  if (poller) clearInterval(poller);
  poller = null;
}

function render() {
  const d = online.detail;
  if (!d) return;
  const status_ = Object.entries(d.status).map(([k, v]) => `${k} ${v}`).join(", ");
  $("#on-detail").replaceChildren(el("span", { class: `badge state-${d.state}`, id: "on-state" }, d.state), el("span", {}, ` ${d.style}, period ${fmt(d.period)} s, ${d.cycles} cycles, ${status_}; parameters: ${Object.entries(d.parameters).map(([k, v]) => `${k}=${v}`).join(", ")}; knowledge base ${d.knowledge_base.origin} (${d.knowledge_base.sha256.slice(0, 10)}…), ${d.downloads} download(s)`));
  const rows = [];
  for (const [name, v] of Object.entries(d.inputs)) rows.push(el("tr", {}, el("th", {}, `input ${name}`), el("td", { class: "num", id: `on-in-${name}` }, fmt(v)), el("td", {}, name in d.forced ? `forced ${fmt(d.forced[name])}` : "")));
  for (const [name, v] of Object.entries(d.outputs)) rows.push(el("tr", {}, el("th", {}, `output ${name}`), el("td", { class: "num", id: `on-out-${name}`, "data-value": v ?? "" }, fmt(v)), el("td", {}, "")));
  $("#on-values tbody").replaceChildren(...rows);
  const force = $("#on-force-input");
  if (force.options.length !== Object.keys(d.inputs).length) force.replaceChildren(...Object.keys(d.inputs).map((n) => el("option", { value: n }, n)));
}

async function command(action, extra = {}) {
  try {
    await post("/api/online/command", { ...creds(), action, ...extra });
    status(`${action}: done`);
    await read();
  } catch (err) {
    status(err.message, "error");
  }
}

async function download() {
  if (!online.url || !online.instance) return status("connect and pick an instance first", "error");
  if (!state.doc) return;
  let diff;
  try {
    diff = await post("/api/online/diff", body(creds()));
  } catch (err) {
    return status(err.message, "error");
  }
  const lines = diffLines(diff.running.fcl, diff.edited);
  const changes = lines.filter((l) => l.op !== " ").length;
  const pre = el("pre", { class: "diff", id: "download-diff" });
  for (const l of lines) pre.append(el("span", { class: l.op === "+" ? "add" : l.op === "-" ? "del" : "same" }, `${l.op} ${l.line}\n`));
  const content = el("div", {}, el("p", {}, `Instance ${online.instance} runs ${diff.running.origin} (${diff.running.format}). ${changes ? `${changes} line(s) differ` : "The knowledge bases are the same"}; − running, + edited:`), pre);
  const answer = await confirmDialog(`Download to ${online.instance}?`, content, [["cancel", "Cancel"], ["download", "Download"]]);
  if (answer !== "download") return;
  try {
    const res = await post("/api/online/download", body(creds()));
    status(`downloaded to ${online.instance}: ${res.procedure}`);
    await read();
  } catch (err) {
    status(err.message, "error");
  }
}

export function init() {
  for (const button of document.querySelectorAll("#on-commands button")) button.dataset.title = button.title || "";
  $("#on-connect").addEventListener("click", connect);
  $("#on-disconnect").addEventListener("click", disconnect);
  $("#on-instance").addEventListener("change", (e) => {
    online.instance = e.target.value;
    renderConnection();
    read();
  });
  $("#on-token").addEventListener("change", (e) => {
    online.token = e.target.value.trim() || null;
    renderConnection();
  });
  $("#on-start").addEventListener("click", () => command("start"));
  $("#on-stop").addEventListener("click", () => command("stop"));
  $("#on-auto").addEventListener("click", () => command("auto"));
  $("#on-manual").addEventListener("click", () => command("manual"));
  $("#on-force").addEventListener("click", () => {
    const value = parseFloat($("#on-force-value").value);
    if (!Number.isFinite(value)) return status("give the forced value", "error");
    command("force", { target: $("#on-force-input").value, value });
  });
  $("#on-release").addEventListener("click", () => command("release", { target: $("#on-force-input").value }));
  $("#on-download").addEventListener("click", download);
  on("report", renderConnection);
  renderConnection();
}

export function shown() {
  renderConnection();
  if (online.url && online.instance) read();
}
