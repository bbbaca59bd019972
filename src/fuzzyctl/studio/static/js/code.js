// A code editor for FCL: a plain <textarea> (so every browser editing key works) over a
// highlighted copy of the text, with a gutter of line numbers in which every line a
// diagnostic names carries a mark (hover: the messages).  Used by the FCL text view and
// the rule text editor.

const KEYWORDS = new Set("FUNCTION_BLOCK END_FUNCTION_BLOCK VAR_INPUT VAR_OUTPUT VAR END_VAR FUZZIFY END_FUZZIFY DEFUZZIFY END_DEFUZZIFY RULEBLOCK END_RULEBLOCK OPTIONS END_OPTIONS OPTION END_OPTION TERM RANGE METHOD DEFAULT ACCU ACT AND OR NOT IF THEN IS WITH RULE NC".split(" "));
const TYPES = new Set("REAL LREAL INT DINT SINT UINT WORD BOOL".split(" "));
const TOKEN = /(\(\*[\s\S]*?(?:\*\)|$)|\/\*[\s\S]*?(?:\*\/|$)|\/\/[^\n]*)|([A-Za-z_][A-Za-z0-9_]*)|(-?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?)|(:=|\.\.|[;:(),])/g;

export function escape(s) {
  return s.replace(/&/g, "&amp;").replace(/</g, "&lt;").replace(/>/g, "&gt;");
}

/** The worst severity per line: Map(line -> "error" | "warning" | "note"). */
export function marks(diagnostics) {
  const out = new Map();
  for (const d of diagnostics || []) {
    if (!d.line) continue;
    const old = out.get(d.line);
    if (old === "error" || (old === "warning" && d.severity !== "error")) continue;
    out.set(d.line, d.severity);
  }
  return out;
}

/** The text as highlighted HTML.  ``window`` ([first, last] line numbers, 1-based) limits
 * the highlighting to those lines; the others stay plain text, which the browser lays out
 * far faster (a 500-rule text has 8000 tokens). */
export function highlight(text, diagnostics = [], window = null) {
  if (window) {
    const lines = text.split("\n");
    const [first, last] = [Math.max(1, window[0]), Math.min(lines.length, window[1])];
    const before = lines.slice(0, first - 1).join("\n");
    const inside = lines.slice(first - 1, last).join("\n");
    const after = lines.slice(last).join("\n");
    const shifted = (diagnostics || []).filter((d) => d.line >= first && d.line <= last).map((d) => ({ ...d, line: d.line - first + 1 }));
    const middle = highlight(inside, shifted).slice(0, -1);
    return (first > 1 ? escape(before) + "\n" : "") + middle + (last < lines.length ? "\n" + escape(after) : "") + "\n";
  }
  let html = "";
  let last = 0;
  for (const m of text.matchAll(TOKEN)) {
    html += escape(text.slice(last, m.index));
    const [tok, comment, word, number, punct] = m;
    if (comment) html += `<span class="tk-comment">${escape(tok)}</span>`;
    else if (word && KEYWORDS.has(word.toUpperCase())) html += `<span class="tk-keyword">${tok}</span>`;
    else if (word && TYPES.has(word.toUpperCase())) html += `<span class="tk-type">${tok}</span>`;
    else if (word) html += `<span class="tk-name">${tok}</span>`;
    else if (number) html += `<span class="tk-number">${tok}</span>`;
    else if (punct) html += `<span class="tk-punct">${escape(tok)}</span>`;
    last = m.index + tok.length;
  }
  html += escape(text.slice(last));
  // mark the lines diagnostics point at (comments may span lines, so mark after tokens)
  const lineMarks = marks(diagnostics);
  const lines = html.split("\n");
  return lines.map((line, i) => (lineMarks.has(i + 1) && lineMarks.get(i + 1) !== "note" ? `<span class="line-${lineMarks.get(i + 1)}">${line || " "}</span>` : line)).join("\n") + "\n";
}

export class CodeEditor {
  /** ``root``: the .code element holding .gutter, pre and textarea; ``onInput`` is called
   * (debounced by ``delay`` ms) with the text after each change. */
  constructor(root, { onInput, delay = 300 } = {}) {
    this.root = root;
    this.input = root.querySelector("textarea");
    this.pre = root.querySelector("pre");
    this.gutter = root.querySelector(".gutter");
    this.diagnostics = [];
    this.lineCount = 0;
    let timer = null;
    let frame = null;
    this.input.addEventListener("input", () => {
      // one repaint per frame however many input events come (a paste of 500 lines may
      // fire one per line), without the marks of the text that was there before
      if (frame === null) {
        frame = requestAnimationFrame(() => {
          frame = null;
          this.paint([]);
        });
      }
      clearTimeout(timer);
      if (onInput) timer = setTimeout(() => onInput(this.input.value), delay);
    });
    this.input.addEventListener("scroll", () => {
      this.syncScroll();
      // scrolled past the highlighted lines: highlight the new ones
      const [first, last] = this.visibleLines();
      const lines = this.lineCount || 0;
      const [a, b] = this.highlighted || [0, 0];
      if ((first > 1 && first - 0 < a) || (last < lines && last > b)) {
        if (frame === null) {
          frame = requestAnimationFrame(() => {
            frame = null;
            this.paint(this.diagnostics);
          });
        }
      }
    });
    this.input.addEventListener("keydown", (e) => {
      if (e.key === "Tab" && !e.shiftKey && !e.ctrlKey && !e.altKey) {
        // indent; Escape then Tab leaves the editor (keyboard users keep a way out)
        if (this.input.dataset.escaped === "true") return;
        e.preventDefault();
        this.input.setRangeText("    ", this.input.selectionStart, this.input.selectionEnd, "end");
        this.input.dispatchEvent(new Event("input"));
      }
      this.input.dataset.escaped = String(e.key === "Escape");
    });
  }

  get value() {
    return this.input.value;
  }

  set value(text) {
    if (this.input.value !== text) this.input.value = text;
    this.paint(this.diagnostics);
  }

  /** Redraw the highlighting and the gutter with these diagnostics (line numbers of this
   * text). */
  paint(diagnostics) {
    this.diagnostics = diagnostics || [];
    const [first, last] = this.visibleLines();
    // a margin of a screenful either side of what is in view
    const screen = last - first;
    this.highlighted = [first - screen, last + screen];
    this.pre.innerHTML = highlight(this.input.value, this.diagnostics, this.highlighted);
    this.paintGutter();
    this.syncScroll();
  }

  /** The lines in view (1-based, first and last). */
  visibleLines() {
    const lineHeight = parseFloat(getComputedStyle(this.input).lineHeight) || 19;
    const first = Math.floor(this.input.scrollTop / lineHeight) + 1;
    const shown = Math.ceil((this.input.clientHeight || 600) / lineHeight);
    return [first, first + shown];
  }

  paintGutter() {
    const count = this.input.value.split("\n").length;
    const lineMarks = marks(this.diagnostics);
    const byLine = new Map();
    for (const d of this.diagnostics) if (d.line) byLine.set(d.line, [...(byLine.get(d.line) || []), `${d.severity}: ${d.message}`]);
    const rows = [];
    for (let i = 1; i <= count; i++) {
      const mark = lineMarks.get(i);
      const title = byLine.has(i) ? ` title="${escape(byLine.get(i).join("\n")).replace(/"/g, "&quot;")}"` : "";
      rows.push(`<div${mark ? ` class="${mark}"` : ""}${title} data-line="${i}">${i}</div>`);
    }
    this.gutter.innerHTML = rows.join("");
    this.lineCount = count;
  }

  syncScroll() {
    this.pre.scrollTop = this.input.scrollTop;
    this.pre.scrollLeft = this.input.scrollLeft;
    this.gutter.scrollTop = this.input.scrollTop;
  }

  /** Select line ``line`` and scroll it into view. */
  goToLine(line) {
    const lines = this.input.value.split("\n");
    const offset = lines.slice(0, line - 1).reduce((n, l) => n + l.length + 1, 0);
    this.input.focus();
    this.input.setSelectionRange(offset, offset + (lines[line - 1] || "").length);
    const lineHeight = parseFloat(getComputedStyle(this.input).lineHeight) || 18;
    this.input.scrollTop = Math.max(0, (line - 5) * lineHeight);
    this.syncScroll();
  }
}
