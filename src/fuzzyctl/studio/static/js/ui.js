// Small DOM helpers shared by the views: element creation, dialogs, diagnostic lists.
import { emit } from "./state.js";

export const $ = (selector, root = document) => root.querySelector(selector);

export function el(tag, attrs = {}, ...children) {
  const node = document.createElement(tag);
  for (const [key, value] of Object.entries(attrs)) {
    if (value === null || value === undefined || value === false) continue;
    if (key.startsWith("on")) node.addEventListener(key.slice(2), value);
    else if (key === "dataset") Object.assign(node.dataset, value);
    else node.setAttribute(key, value === true ? "" : value);
  }
  for (const child of children) if (child !== null && child !== undefined) node.append(child);
  return node;
}

/** Show a <dialog>; resolves with the value of the button that closed it. */
export function openDialog(selector, focus = null) {
  const dialog = $(selector);
  return new Promise((resolve) => {
    dialog.returnValue = "cancel";
    // Enter in a field answers with the primary button (the form's implicit submission
    // would pick the first button, Cancel)
    const onKey = (e) => {
      const primary = dialog.querySelector("button.primary");
      if (e.key === "Enter" && e.target.tagName === "INPUT" && primary) {
        e.preventDefault();
        dialog.close(primary.value);
      }
    };
    dialog.addEventListener("keydown", onKey);
    dialog.addEventListener(
      "close",
      () => {
        dialog.removeEventListener("keydown", onKey);
        resolve(dialog.returnValue);
      },
      { once: true },
    );
    dialog.showModal();
    if (focus) focus.focus();
  });
}

/** A question with buttons [[value, label], ...]; the last one is the default. */
export function confirmDialog(title, content, buttons) {
  $("#confirm-title").textContent = title;
  const bodyNode = $("#confirm-body");
  bodyNode.replaceChildren(typeof content === "string" ? el("p", {}, content) : content);
  const menu = $("#confirm-buttons");
  menu.replaceChildren(...buttons.map(([value, label], i) => el("button", { value, class: i === buttons.length - 1 ? "primary" : null, id: `confirm-${value}` }, label)));
  return openDialog("#dlg-confirm", menu.lastChild);
}

/** Fill a list with diagnostics; each item leads to the element it concerns. */
export function fillDiagnostics(list, diagnostics, { onClick = goTo } = {}) {
  list.replaceChildren();
  for (const d of diagnostics) {
    const where = d.line ? `${d.line}${d.column ? ":" + d.column : ""}` : "";
    const item = el("li", { class: d.severity, tabindex: "0", title: d.element || "" }, `${d.severity}${where ? " " + where : ""}: ${d.message}`);
    item.addEventListener("click", () => onClick(d));
    item.addEventListener("keydown", (e) => e.key === "Enter" && onClick(d));
    list.append(item);
  }
}

function goTo(d) {
  const e = d.element || "";
  if (e.startsWith("term:") || e.startsWith("var:")) {
    const [, name, term] = e.split(":");
    emit("show", { view: "variable", target: { name, term } });
  } else if (e.startsWith("rule:") || e.startsWith("ruleblock:")) {
    const [, block, rule] = e.split(":");
    emit("show", { view: "rules", target: { block: +block, rule: rule === undefined ? null : +rule } });
  } else if (d.line) {
    emit("show", { view: "text", target: { line: d.line } });
  }
}

// plotly.js (3.5 MB) is read when the first chart is drawn, not before the studio starts:
// the project, rule and text views are ready at once.
let plotlyLoading = null;
export function plotlyReady() {
  if (window.Plotly) return Promise.resolve(window.Plotly);
  if (!plotlyLoading) {
    plotlyLoading = new Promise((resolve, reject) => {
      const bar = document.getElementById("busy");
      if (bar) bar.hidden = false;
      const script = document.createElement("script");
      script.src = "/vendor/plotly.min.js";
      script.onload = () => {
        if (bar && document.body.dataset.busy !== "true") bar.hidden = true;
        resolve(window.Plotly);
      };
      script.onerror = () => reject(new Error("plotly.js could not be loaded"));
      document.head.append(script);
    });
  }
  return plotlyLoading;
}

/** plotly with the studio's look.  Before plotly.js is there the chart says it is coming,
 * and only the last drawing asked for is made once it is. */
export function plot(node, traces, layout = {}, config = {}) {
  const base = {
    margin: { l: 50, r: 20, t: 20, b: 40 },
    paper_bgcolor: "#fff",
    plot_bgcolor: "#fff",
    font: { family: "system-ui, sans-serif", size: 12 },
    showlegend: false,
  };
  const args = [traces, { ...base, ...layout }, { displaylogo: false, responsive: true, ...config }];
  if (window.Plotly) return window.Plotly.react(node, ...args);
  const first = !node._pendingPlot;
  node._pendingPlot = args;
  if (first && !node.querySelector(".plot-container")) node.textContent = "loading the charts (plotly.js)…";
  return plotlyReady().then((Plotly) => {
    const pending = node._pendingPlot;
    node._pendingPlot = null;
    if (!pending) return null;
    if (!node.querySelector(".plot-container")) node.textContent = "";
    return Plotly.react(node, ...pending);
  });
}

/** Axis ticks that never collide: plotly picks at most ``n`` ticks. */
export function ticks(n = 6) {
  return { nticks: n, automargin: true };
}

export const COLORS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf"];
