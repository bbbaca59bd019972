// Resizable panes: every splitter between two panes of a row resizes the fixed-width
// pane next to it (mouse, or the arrow keys when it has the focus); the check panel has
// its own splitter and can be hidden.  Sizes are remembered in the browser.
const KEY = "fuzzyctl-studio.panes";

function saved() {
  try {
    return JSON.parse(localStorage.getItem(KEY) || "{}");
  } catch (_) {
    return {};
  }
}
function remember(name, value) {
  const all = saved();
  all[name] = value;
  try {
    localStorage.setItem(KEY, JSON.stringify(all));
  } catch (_) {
    /* private mode: not remembered */
  }
}

/** Charts (plotly's responsive mode) follow a window resize; a pane resize is one too. */
export function relayout() {
  window.dispatchEvent(new Event("resize"));
}

function bind(splitter, name, apply, current, { min = 160, max = 900, invert = false } = {}) {
  let start = null;
  splitter.addEventListener("pointerdown", (e) => {
    if (e.button !== 0) return;
    e.preventDefault();
    start = { x: e.clientX, width: current() };
    splitter.classList.add("dragging");
    splitter.setPointerCapture(e.pointerId);
  });
  splitter.addEventListener("pointermove", (e) => {
    if (!start) return;
    const delta = (e.clientX - start.x) * (invert ? -1 : 1);
    apply(Math.max(min, Math.min(max, start.width + delta)));
  });
  const end = () => {
    if (!start) return;
    start = null;
    splitter.classList.remove("dragging");
    remember(name, current());
    relayout();
  };
  splitter.addEventListener("pointerup", end);
  splitter.addEventListener("pointercancel", end);
  splitter.addEventListener("keydown", (e) => {
    if (e.key !== "ArrowLeft" && e.key !== "ArrowRight") return;
    e.preventDefault();
    const step = (e.key === "ArrowRight" ? 20 : -20) * (invert ? -1 : 1);
    apply(Math.max(min, Math.min(max, current() + step)));
    remember(name, current());
    relayout();
  });
}

export function init() {
  const sizes = saved();
  for (const row of document.querySelectorAll(".pane-row[data-split]")) {
    const splitter = row.querySelector(":scope > .splitter");
    const fixed = row.querySelector(":scope > .side-pane");
    if (!splitter || !fixed) continue;
    const name = row.dataset.split;
    // the fixed pane right of the splitter grows when the splitter moves left
    const invert = splitter.compareDocumentPosition(fixed) & Node.DOCUMENT_POSITION_FOLLOWING;
    const apply = (w) => fixed.style.setProperty("--pane-width", `${Math.round(w)}px`);
    const current = () => fixed.getBoundingClientRect().width;
    if (sizes[name]) apply(sizes[name]);
    bind(splitter, name, apply, current, { invert: !!invert });
  }
  const layout = document.getElementById("layout");
  const side = document.getElementById("side");
  const applySide = (w) => layout.style.setProperty("--side-width", `${Math.round(w)}px`);
  if (sizes.side) applySide(sizes.side);
  bind(document.getElementById("side-splitter"), "side", applySide, () => side.getBoundingClientRect().width, { min: 200, max: 700, invert: true });
  const toggle = document.getElementById("side-toggle");
  const setOpen = (open) => {
    layout.classList.toggle("side-closed", !open);
    toggle.setAttribute("aria-expanded", String(open));
    toggle.textContent = open ? "Check ▸" : "◂ Check";
    remember("sideOpen", open);
    relayout();
  };
  if (sizes.sideOpen === false) setOpen(false);
  toggle.addEventListener("click", () => setOpen(layout.classList.contains("side-closed")));
}
