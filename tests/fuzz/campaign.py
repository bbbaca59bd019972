"""A seeded mutation fuzzer over real model files (issue 14, point 5).

Seeds are the examples and the vendored jFuzzyLogic/fuzzylite files (tests/data), and the
examples as fuzzyctl JSON; ``--corpus`` adds the real-world corpus of ../shared.  Each
mutant is one to three edits of a seed - deletions, duplications, dangerous tokens
(``NOT``, ``(``, ``inf``, ``nan``, 5001-digit numbers, quotes, NUL, CR), nesting bombs,
repeated lines, CR-only line ends, 200,000-character fields - and goes through what a user
would do with it: ``fuzzyctl.load``, ``compile``, ``evaluate`` and ``evaluate_batch`` on
ordinary and extreme inputs (which must agree: the same number, or both NaN), ``explain``, a
conversion, code generation, and one CLI command (check / convert / eval / explain).
Every model that loads is also checked path by path against the reference interpreter
(:mod:`tests.fuzz.differential`), and ``--systems`` seeded random systems
(:mod:`tests.fuzz.systems`) follow the mutants.  The run ends with a table of counts per
source and path; each failure has a one-line replay command (``--replay``).

A mutant fails when it raises anything but a :class:`~fuzzyctl.diagnostics.FuzzyctlError`
(the API) or makes the CLI exit 3 ("crash"), when a path disagrees with the reference
interpreter (``tests.fuzz.differential``: "disagree", with a category per path),
when it runs over ``--timeout`` CPU seconds ("hang"), or when the process grows over
``--memory`` MB ("memory").  Mutants run in worker processes so that a hang or a runaway
allocation is contained; the verdict does not depend on scheduling.

usage: python -m tests.fuzz.campaign [--mutants 3000] [--systems 300] [--seed 1] [--corpus]
                                     [--workers 2] [--save DIR] [--replay FILE|system:S:K]
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import io
import itertools
import math
import multiprocessing as mp
import os
import random
import re
import resource
import sys
import tempfile
import time
import traceback
from collections import Counter
from collections.abc import Iterator
from dataclasses import dataclass, field
from multiprocessing.connection import Connection
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
SEED_FORMATS = {".fcl": "fcl", ".fis": "fis", ".fll": "fll", ".fpl": "fpl", ".xfuz": "xfuz", ".json": "json"}
FORMATS = ("fcl", "fis", "fll", "json", "fpl", "xfuz")
EXTREMES = ["1e20", "-1e20", "1e308", "1e309", "-1e309", "inf", "-inf", "nan", "NaN", "Infinity", "-0",
            "1e-320", "9" * 5001, "4" * 400, "0x10", "1_0", "0", "-1"]  # fmt: skip
TOKENS = ["NOT ", "not ", "(", ")", "((", "))", "AND ", "OR ", "IS ", " is ", ";", ":", ",", "'", '"',
          "\x00", "\r", "\n", "\t", "\u2028", "\ufeff", "\x85", "é", "[", "]", "{", "}", "*)", "(*", "*/",
          "/*", "//", "#", "%", "=", ":=", "..", "WITH ", "END ", "END_RULEBLOCK", "RULE 9 : ",
          "TERM t := ", "inf", "nan", "-inf", "1e309", "9" * 5001, "x" * 300]  # fmt: skip


# --------------------------------------------------------------------------- seeds


@dataclass(frozen=True)
class Seed:
    name: str
    fmt: str
    text: str


def _fmt_of(path: Path) -> str | None:
    name = path.name.lower()
    if name.endswith(".csv.xfuz"):
        return "xfuz"
    return SEED_FORMATS.get(path.suffix.lower())


def seeds(corpus: bool = False) -> list[Seed]:
    """Every seed file (examples, tests/data, with ``corpus`` the shared corpus) and the
    examples written as JSON."""
    paths = [p for p in sorted((ROOT / "examples").iterdir()) if p.is_file()]
    paths += sorted(p for p in (ROOT / "tests" / "data").rglob("*") if p.is_file())
    if corpus:
        from tests.extras import extra_files

        paths += extra_files("corpus", "corpus", pattern="*", recursive=True)
    out: list[Seed] = []
    for p in paths:
        fmt = _fmt_of(p)
        if fmt is None:
            continue
        out.append(Seed(str(p.relative_to(ROOT)) if p.is_relative_to(ROOT) else p.name, fmt, _decode(p)))
    import fuzzyctl
    from fuzzyctl.formats.json import writer as fj

    for p in sorted((ROOT / "examples").glob("*.fcl")):
        text = fj.dumps(fuzzyctl.load(p))
        out.append(Seed(f"{p.relative_to(ROOT)} as JSON", "json", text))
    return out


def _decode(path: Path) -> str:
    from fuzzyctl.formats import decode

    return decode(path.read_bytes())


# --------------------------------------------------------------------------- mutation

NUMBER_RE = re.compile(r"(?<![\w.])[-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?")
_WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def _pos(rng: random.Random, text: str) -> int:
    return rng.randrange(len(text) + 1)


def _slice(rng: random.Random, text: str, longest: int = 60) -> tuple[int, int]:
    a = _pos(rng, text)
    return a, min(len(text), a + rng.randint(1, longest))


def _op_delete(rng: random.Random, text: str) -> tuple[str, str]:
    a, b = _slice(rng, text)
    return text[:a] + text[b:], f"delete [{a}:{b}]"


def _op_duplicate(rng: random.Random, text: str) -> tuple[str, str]:
    a, b = _slice(rng, text)
    return text[:b] + text[a:b] + text[b:], f"duplicate [{a}:{b}]"


def _op_insert(rng: random.Random, text: str) -> tuple[str, str]:
    tok = rng.choice(TOKENS)
    a = _pos(rng, text)
    return text[:a] + tok + text[a:], f"insert {tok[:12]!r} at {a}"


def _op_number(rng: random.Random, text: str) -> tuple[str, str]:
    nums = list(NUMBER_RE.finditer(text))
    if not nums:
        return _op_insert(rng, text)
    m = rng.choice(nums)
    new = rng.choice(EXTREMES)
    return text[: m.start()] + new + text[m.end() :], f"number {m.group()!r} -> {new[:12]!r} at {m.start()}"


def _op_rename(rng: random.Random, text: str) -> tuple[str, str]:
    words = list(_WORD.finditer(text))
    if len(words) < 2:
        return _op_delete(rng, text)
    m, other = rng.choice(words), rng.choice(words)
    return text[: m.start()] + other.group() + text[m.end() :], f"word {m.group()!r} -> {other.group()!r}"


def _op_nest(rng: random.Random, text: str) -> tuple[str, str]:
    depth = rng.choice([3, 60, 500, 1200, 20_000])
    a, b = _slice(rng, text, 30)
    kind = rng.choice(["paren", "not", "bracket"])
    if kind == "paren":
        new = "(" * depth + text[a:b] + ")" * depth
    elif kind == "not":
        new = "NOT " * depth + text[a:b] if rng.random() < 0.5 else "not " * depth + text[a:b]
    else:
        new = "[" * depth + text[a:b] + "]" * depth
    return text[:a] + new + text[b:], f"nest {kind} x{depth} at {a}"


def _op_repeat_line(rng: random.Random, text: str) -> tuple[str, str]:
    lines = text.split("\n")
    k = rng.randrange(len(lines))
    n = rng.choice([2, 10, 300, 5000])
    lines[k : k + 1] = [lines[k]] * n
    return "\n".join(lines), f"repeat line {k + 1} x{n}"


def _op_line_ends(rng: random.Random, text: str) -> tuple[str, str]:
    end = rng.choice(["\r", "\r\n", "\u2028", ""])
    return text.replace("\n", end), f"line ends -> {end!r}"


def _op_truncate(rng: random.Random, text: str) -> tuple[str, str]:
    a = _pos(rng, text)
    return text[:a], f"truncate at {a}"


def _op_char(rng: random.Random, text: str) -> tuple[str, str]:
    if not text:
        return _op_insert(rng, text)
    a = rng.randrange(len(text))
    ch = chr(
        rng.choice(
            [0, 1, 9, 13, 27, 34, 39, 40, 41, 59, 0x85, 0xA0, 0x2028, 0xFEFF, 0xFFFF, rng.randrange(32, 127)]
        )
    )
    return text[:a] + ch + text[a + 1 :], f"char at {a} -> {ch!r}"


def _op_big_field(rng: random.Random, text: str) -> tuple[str, str]:
    a = _pos(rng, text)
    return text[:a] + "x" * 200_000 + text[a:], f"200000-char field at {a}"


OPERATORS = [
    (_op_delete, 4),
    (_op_duplicate, 3),
    (_op_insert, 5),
    (_op_number, 5),
    (_op_rename, 3),
    (_op_nest, 2),
    (_op_repeat_line, 1),
    (_op_line_ends, 1),
    (_op_truncate, 1),
    (_op_char, 3),
    (_op_big_field, 1),
]


@dataclass(frozen=True)
class Mutant:
    index: int
    seed: str
    fmt: str
    ops: tuple[str, ...]
    text: str
    plan: int  # which secondary actions run (conversion target, codegen, CLI command)
    system: Any = None  # a random FunctionBlock (tests.fuzz.systems) instead of a mutated file
    full: bool = False  # run every differential path (a replay), not a sample of the costly ones
    rates: tuple[float, float] = (0.1, 0.25)  # share of loaded models through generated C, the CLI


def mutants(all_seeds: list[Seed], n: int, seed: int) -> Iterator[Mutant]:
    """``n`` mutants, the same for the same ``seed``."""
    rng = random.Random(seed)
    ops, weights = zip(*OPERATORS, strict=True)
    for index in range(n):
        s = rng.choice(all_seeds)
        text, done = s.text, []
        for _ in range(rng.choice([1, 1, 2, 3])):
            op = rng.choices(ops, weights)[0]
            text, what = op(rng, text)
            done.append(what)
        yield Mutant(index, s.name, s.fmt, tuple(done), text, rng.randrange(1 << 30))


def random_systems(n: int, seed: int, first_index: int = 0) -> Iterator[Mutant]:
    """``n`` random systems (:mod:`tests.fuzz.systems`), written as fuzzyctl JSON for the
    CLI and for replay."""
    from fuzzyctl.formats.json import writer as fj
    from fuzzyctl.model import Document
    from tests.fuzz import systems

    rng = random.Random(f"systems:{seed}")
    for k in range(n):
        fb = systems.system(k, seed)
        try:
            text = fj.dumps(Document((fb,)))
        except Exception as exc:  # a model the JSON writer refuses: still evaluated in-process
            text = f"// the JSON writer refused this system: {exc}"
        yield Mutant(first_index + k, f"random system {k}", "json", (), text, rng.randrange(1 << 30), fb)


# --------------------------------------------------------------------------- running one


@dataclass
class Outcome:
    index: int
    kind: str  # ok, refused, crash, disagree, hang, memory
    detail: str = ""
    rss_mb: float = 0.0
    steps: list[str] = field(default_factory=list)
    loaded: bool = False
    compared: set[str] = field(default_factory=set)  # differential paths compared
    findings: list[tuple[str, str]] = field(default_factory=list)  # (category, detail)


class _Failure(Exception):
    def __init__(self, kind: str, detail: str) -> None:
        super().__init__(detail)
        self.kind = kind


def _api(step: str, fn: Any, *args: Any, **kwargs: Any) -> Any:
    """Run ``fn``; a project error is a refusal (None), anything else a crash."""
    from fuzzyctl.diagnostics import FuzzyctlError

    try:
        return fn(*args, **kwargs)
    except FuzzyctlError:
        return None
    except RecursionError as exc:  # a subclass of RuntimeError: named for the report
        raise _Failure("crash", f"{step}: RecursionError: {str(exc)[:200]}") from exc
    except Exception as exc:
        tb = traceback.extract_tb(exc.__traceback__)[-1]
        where = f"{Path(tb.filename).name}:{tb.lineno}"
        raise _Failure("crash", f"{step}: {type(exc).__name__} at {where}: {str(exc)[:200]}") from exc


def _values(doc: Any, block: Any, name: str, k: int) -> float:
    """Input value ``k`` for variable ``name``: ordinary ones from its range, then extremes."""
    lo, hi = 0.0, 1.0
    fz = block.fuzzify_block(name)
    var = block.variable(name)
    rng_ = getattr(var, "range", None) or getattr(fz, "range", None)
    if rng_ is not None:
        with contextlib.suppress(TypeError, ValueError, AttributeError):
            lo, hi = float(rng_.low), float(rng_.high)
    if not (math.isfinite(lo) and math.isfinite(hi)):
        lo, hi = 0.0, 1.0
    choices = [lo + 0.37 * (hi - lo), lo, hi, 1e20, -1e20, 0.0, 1e308, -1e308]
    return choices[k % len(choices)]


def _agree(a: float, b: float) -> bool:
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    if math.isinf(a) or math.isinf(b):
        return a == b
    return abs(a - b) <= 1e-6 * max(1.0, abs(a), abs(b))


def _engine(doc: Any, m: Mutant, steps: list[str], findings: list[tuple[str, str]] | None = None) -> None:
    """compile (default backend), evaluate and evaluate_batch on ordinary and extreme inputs
    (1e20, 1e308: they must agree, to 1e-6 relative), explain: for crashes first."""
    import numpy as np

    import fuzzyctl

    rng = random.Random(m.plan)
    for fb in doc.blocks[:2]:
        steps.append(f"compile {fb.name}")
        ctl = _api("compile", fuzzyctl.compile, doc, block=fb.name)
        if ctl is None:
            continue
        degree = {spec.name for spec in ctl.plan.inputs if spec.degree}
        for k in range(3):
            vec = {n: (0.5 if n in degree else _values(doc, fb, n, k + rng.randrange(6))) for n in ctl.inputs}
            steps.append(f"evaluate {vec}")
            ctl.reset()
            one = _api("evaluate", ctl.evaluate, vec)
            ctl.reset()
            many = _api("evaluate_batch", ctl.evaluate_batch, {n: np.array([v]) for n, v in vec.items()})
            if one is not None and many is not None:
                if any(len(many[name]) != 1 for name in one) and findings is not None:
                    findings.append(("disagree:numpy", f"a batch of one row at {vec} gave {many!r}"))
                    continue
                for name, value in one.items():
                    if not _agree(float(value), float(many[name][0])) and findings is not None:
                        findings.append(
                            (
                                "disagree:scalar-batch",
                                f"{name} at {vec}: evaluate {value!r}, batch {many[name][0]!r}",
                            )
                        )
                        break
            if k == 0:
                ctl.reset()
                _api("explain", ctl.explain, vec)


def _secondary(doc: Any, m: Mutant, steps: list[str]) -> None:
    from fuzzyctl import codegen, formats

    rng = random.Random(m.plan + 1)
    target = rng.choice(FORMATS)
    steps.append(f"convert to {target}")
    _api(f"convert to {target}", formats.convert, doc, target, lossy=True)
    if rng.random() < 0.3:
        lang = rng.choice(["c", "st"])
        steps.append(f"codegen {lang}")
        _api(f"codegen {lang}", codegen.generate_c if lang == "c" else codegen.generate_st, doc)


def _cli(m: Mutant, path: Path, steps: list[str]) -> None:
    from fuzzyctl.cli.app import main

    rng = random.Random(m.plan + 2)
    cmd = rng.choice(
        ["check", "convert", "eval", "explain"] if m.fmt == "fcl" else ["convert", "eval", "explain"]
    )
    out = path.with_name("out." + rng.choice(FORMATS))
    args = {
        "check": ["check", str(path)],
        "convert": ["convert", str(path), str(out), "--lossy", "--from", m.fmt],
        "eval": ["eval", str(path)],
        "explain": ["explain", str(path)],
    }[cmd]
    steps.append("cli " + " ".join(args[:1]))
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(buf):
        code = main(args)
    if code == 3 or code not in (0, 1, 2):
        lines = [
            ln for ln in buf.getvalue().splitlines() if "internal error" in ln
        ] or buf.getvalue().splitlines()
        raise _Failure("crash", f"cli {cmd} exit {code}: {(lines[0] if lines else '')[:300]}")


def _differential(doc: Any, m: Mutant, path: Path, steps: list[str], out: Outcome) -> None:
    """Every backend, explain, (sampled) the CLI and generated C against the reference
    interpreter (:mod:`tests.fuzz.differential`) on the first two blocks."""
    from tests.fuzz import differential

    rng = random.Random(m.plan + 3)
    for fb in doc.blocks[:2]:
        extra = differential.ExtraPaths(
            cli_path=path if not m.text.startswith("// ") else None,
            cli_fmt=m.fmt,
            cli=m.full or rng.random() < m.rates[1],
            c=m.full or rng.random() < m.rates[0],
        )
        steps.append(f"differential {fb.name}" + (" +cli" if extra.cli else "") + (" +c" if extra.c else ""))
        try:
            res = differential.check(doc, fb.name if len(doc.blocks) > 1 else None, rng, extra)
        except RecursionError as exc:
            raise _Failure("crash", f"differential: RecursionError: {str(exc)[:200]}") from exc
        except Exception as exc:
            tb = traceback.extract_tb(exc.__traceback__)[-1]
            where = f"{Path(tb.filename).name}:{tb.lineno}"
            raise _Failure(
                "crash", f"differential: {type(exc).__name__} at {where}: {str(exc)[:200]}"
            ) from exc
        out.compared |= res.compared | res.notes
        out.findings += [(f.category, f"[{fb.name}] {f.detail}") for f in res.findings]


def run_one(m: Mutant, workdir: Path) -> Outcome:
    import fuzzyctl
    from fuzzyctl.model import Document

    steps: list[str] = ["load"]
    out = Outcome(m.index, "refused", steps=steps)
    try:
        ext = {"xfuz": ".xfuz"}.get(m.fmt, "." + m.fmt)
        path = workdir / f"mutant{ext}"
        path.write_text(m.text, encoding="utf-8", errors="surrogatepass")
        doc = (
            Document((m.system,))
            if m.system is not None
            else _api("load", fuzzyctl.load, m.text, format=m.fmt)
        )
        if doc is not None:
            out.loaded = True
            _engine(doc, m, steps, out.findings)
            _differential(doc, m, path, steps, out)
            _secondary(doc, m, steps)
        if m.system is None:
            _cli(m, path, steps)
    except _Failure as f:
        out.kind, out.detail = f.kind, str(f)
        return out
    if out.findings:
        out.kind = "disagree"
        out.detail = "\n    ".join(f"{c}: {d}" for c, d in out.findings)
    else:
        out.kind = "ok" if out.loaded else "refused"
    return out


# --------------------------------------------------------------------------- workers


def _worker(conn: Connection, memory_mb: int) -> None:
    import warnings

    warnings.simplefilter("ignore")
    sys.setrecursionlimit(max(sys.getrecursionlimit(), 1000))
    limit = memory_mb * 4 * 1024 * 1024  # hard stop far above the reported limit
    with contextlib.suppress(ValueError, OSError):
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    with tempfile.TemporaryDirectory(prefix="fuzzyctl-fuzz-") as tmp:
        os.environ["FUZZYCTL_CACHE_DIR"] = tmp
        while True:
            m = conn.recv()
            if m is None:
                return
            _reset_peak_rss()
            try:
                out = run_one(m, Path(tmp))
            except MemoryError:
                out = Outcome(m.index, "memory", "MemoryError")
            except Exception as exc:  # the fuzzer's own checks tripped: still a finding, not a dead worker
                tb = traceback.extract_tb(exc.__traceback__)[-1]
                where = f"{Path(tb.filename).name}:{tb.lineno}"
                out = Outcome(
                    m.index, "crash", f"in the fuzzer at {where}: {type(exc).__name__}: {str(exc)[:200]}"
                )
            out.rss_mb = _peak_rss_mb()
            conn.send(out)


def _reset_peak_rss() -> None:
    """Start this mutant's peak from the current resident size (Linux: clear_refs 5), so that
    a mutant is not charged with what an earlier one or the imports once needed."""
    with contextlib.suppress(OSError):
        Path("/proc/self/clear_refs").write_text("5")


def _peak_rss_mb() -> float:
    """The peak resident size since :func:`_reset_peak_rss` (VmHWM), else the process's."""
    with contextlib.suppress(OSError, ValueError):
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def _cpu_seconds(pid: int) -> float:
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except (OSError, IndexError, ValueError):
        return 0.0


class _Slot:
    def __init__(self, ctx: Any, memory_mb: int) -> None:
        self.conn, child = ctx.Pipe()
        self.proc = ctx.Process(target=_worker, args=(child, memory_mb), daemon=True)
        self.proc.start()
        self.mutant: Mutant | None = None
        self.cpu0 = 0.0
        self.wall0 = 0.0

    def give(self, m: Mutant) -> None:
        self.mutant, self.cpu0, self.wall0 = m, _cpu_seconds(self.proc.pid), time.monotonic()
        self.conn.send(m)

    def stop(self) -> None:
        with contextlib.suppress(OSError, BrokenPipeError):
            self.conn.send(None)
        self.proc.join(5)
        if self.proc.is_alive():
            self.proc.kill()
            self.proc.join()


@dataclass
class Report:
    tried: int = 0
    counts: Counter[str] = field(default_factory=Counter)
    failures: list[tuple[Mutant, Outcome]] = field(default_factory=list)
    peak_rss_mb: float = 0.0
    seconds: float = 0.0
    started: float = field(default_factory=time.monotonic)
    #: (source, row) -> models: source "mutants" or "systems"; rows "tried", "loaded",
    #: "compared", "disagreeing", "compared:<path>" and each finding category
    table: Counter[tuple[str, str]] = field(default_factory=Counter)
    seed: int = 0
    saved: dict[int, Path] = field(default_factory=dict)  # index -> the file written under --save

    def tally(self, m: Mutant, out: Outcome) -> None:
        src = "systems" if m.system is not None else "mutants"
        self.table[src, "tried"] += 1
        self.table[src, "loaded"] += out.loaded
        self.table[src, "compared"] += bool(out.compared)
        self.table[src, "disagreeing"] += bool(out.findings)
        for path in out.compared:
            self.table[src, f"compared:{path}"] += 1
        for cat in {c for c, _ in out.findings}:
            self.table[src, cat] += 1

    def counts_table(self) -> str:
        """Models per source: tried, loaded, compared; per path compared and disagreeing."""
        from tests.fuzz.differential import PATHS

        rows = [("tried", "tried"), ("loaded", "loaded"), ("compared (any path)", "compared"),
                ("disagreeing (any)", "disagreeing")]  # fmt: skip
        cats = sorted({r for _, r in self.table if ":" in r and not r.startswith("compared:")})
        lines = [f"{'':34}{'mutants':>10}{'systems':>10}"]
        for label, key in rows:
            lines.append(f"{label:34}{self.table['mutants', key]:>10}{self.table['systems', key]:>10}")
        for extra in sorted({r[9:] for _, r in self.table if r.startswith("compared:")} - set(PATHS)):
            lines.append(
                f"{extra + ' (models)':34}{self.table['mutants', 'compared:' + extra]:>10}"
                f"{self.table['systems', 'compared:' + extra]:>10}"
            )
        for p in PATHS:
            for label, key in ((f"{p}: compared", f"compared:{p}"), (f"{p}: disagreeing", f"disagree:{p}")):
                lines.append(f"{label:34}{self.table['mutants', key]:>10}{self.table['systems', key]:>10}")
        for cat in cats:
            if cat.startswith("disagree:") and cat[9:] in PATHS:
                continue
            lines.append(f"{cat:34}{self.table['mutants', cat]:>10}{self.table['systems', cat]:>10}")
        return "\n".join(lines)

    @property
    def crashed(self) -> int:
        return self.counts["crash"] + self.counts["disagree"] + self.counts["memory"]

    @property
    def hung(self) -> int:
        return self.counts["hang"]

    def summary(self) -> str:
        kinds = ", ".join(f"{k} {v}" for k, v in sorted(self.counts.items()))
        return (
            f"{self.tried} mutants tried, {self.crashed} crashed (crash/disagree/memory), {self.hung} hung "
            f"[{kinds}]; peak worker RSS {self.peak_rss_mb:.0f} MB; {time.monotonic() - self.started:.0f} s"
        )

    def describe(self, limit: int = 12) -> str:
        lines = []
        for m, o in self.failures[:limit]:
            lines.append(
                f"#{m.index} {o.kind}: {m.seed} ({m.fmt}) + {'; '.join(m.ops)}\n    {o.detail}\n"
                f"    replay: {replay_command(m, self.seed, self.saved.get(m.index))}"
            )
        if len(self.failures) > limit:
            lines.append(f"... and {len(self.failures) - limit} more")
        return "\n".join(lines)


def campaign(
    all_seeds: list[Seed],
    n: int,
    seed: int,
    *,
    workers: int = 2,
    timeout: float = 30.0,
    memory_mb: int = 500,
    save: Path | None = None,
    progress: bool = False,
    n_systems: int = 0,
    rates: tuple[float, float] = (0.1, 0.25),
) -> Report:
    """Run ``n`` mutants over ``workers`` processes; a mutant over ``timeout`` CPU seconds
    (or 30 times that in wall time: the machine may be shared) is a hang, one that leaves
    its worker over ``memory_mb`` resident a memory failure (the worker is replaced).
    ``n_systems`` random systems follow the mutants; ``rates``: the share of loaded models
    also run through generated C and through the CLI (the costly paths)."""
    ctx = mp.get_context("spawn")
    report = Report(seed=seed)
    start = time.monotonic()
    todo = (
        dataclasses.replace(m, rates=rates)
        for m in itertools.chain(mutants(all_seeds, n, seed), random_systems(n_systems, seed, n))
    )
    slots = [_Slot(ctx, memory_mb) for _ in range(workers)]
    pending = True

    def record(m: Mutant, out: Outcome) -> None:
        report.tried += 1
        report.counts[out.kind] += 1
        report.peak_rss_mb = max(report.peak_rss_mb, out.rss_mb)
        report.tally(m, out)
        if out.kind in ("crash", "disagree", "hang", "memory"):
            report.failures.append((m, out))
            if save is not None:
                save.mkdir(parents=True, exist_ok=True)
                kind = "system" if m.system is not None else "mutant"
                target = save / f"{kind}-{seed}-{m.index}-p{m.plan}.{m.fmt}"
                target.write_text(m.text, errors="surrogatepass")
                target.with_suffix(target.suffix + ".txt").write_text(
                    f"{m.seed} + {'; '.join(m.ops)}\n{out.kind}: {out.detail}\n"
                    f"replay: {replay_command(m, seed, target)}\n"
                )
                report.saved[m.index] = target
        if progress and report.tried % 100 == 0:
            print(f"  {report.summary()}", file=sys.stderr, flush=True)

    try:
        for slot in slots:
            m = next(todo, None)
            if m is None:
                pending = False
                break
            slot.give(m)
        while any(s.mutant is not None for s in slots):
            for k, slot in enumerate(slots):
                if slot.mutant is None:
                    continue
                if slot.conn.poll(0.02):
                    m = slot.mutant  # (the slot may be replaced below)
                    try:
                        out: Outcome = slot.conn.recv()
                    except EOFError:  # the worker died (out of memory, a signal)
                        out = Outcome(m.index, "memory", "the worker process died")
                        slot.stop()
                        slots[k] = slot = _Slot(ctx, memory_mb)
                    if out.kind in ("ok", "refused") and out.rss_mb > memory_mb:
                        out.kind, out.detail = "memory", f"worker RSS {out.rss_mb:.0f} MB"
                    record(m, out)
                    if out.kind == "memory" or out.rss_mb > memory_mb:
                        slot.stop()
                        slots[k] = slot = _Slot(ctx, memory_mb)
                    nxt = next(todo, None) if pending else None
                    pending = nxt is not None
                    slot.mutant = None
                    if nxt is not None:
                        slot.give(nxt)
                    continue
                cpu = _cpu_seconds(slot.proc.pid) - slot.cpu0
                wall = time.monotonic() - slot.wall0
                if cpu > timeout or wall > 30 * timeout or not slot.proc.is_alive():
                    detail = f"over {timeout:.0f} s ({cpu:.1f} s CPU, {wall:.1f} s wall)"
                    if not slot.proc.is_alive():
                        detail = "the worker process died"
                    record(
                        slot.mutant,
                        Outcome(slot.mutant.index, "hang" if slot.proc.is_alive() else "memory", detail),
                    )
                    slot.proc.kill()
                    slot.proc.join()
                    slots[k] = slot = _Slot(ctx, memory_mb)
                    nxt = next(todo, None) if pending else None
                    pending = nxt is not None
                    if nxt is not None:
                        slot.give(nxt)
    finally:
        for slot in slots:
            slot.stop()
    report.seconds = time.monotonic() - start
    return report


def replay_command(m: Mutant, seed: int, saved: Path | None = None) -> str:
    """One command line (from the repository root) that runs ``m`` again, every path on."""
    if m.system is not None:
        what = f"system:{seed}:{m.seed.rsplit(' ', 1)[1]}"
    elif saved is not None:
        what = str(saved)
    else:
        what = f"mutant:{seed}:{m.index}  (with --corpus if the run had it)"
    return f"python -m tests.fuzz.campaign --replay {what}"


def replay(spec: str, corpus: bool = False) -> Mutant:
    """The model ``spec`` names: ``system:SEED:K``, ``mutant:SEED:INDEX`` or a file saved
    under ``--save`` (``KIND-SEED-INDEX-pPLAN.EXT``), with every differential path on."""
    kind, _, rest = spec.partition(":")
    if kind == "system":
        s, k = (int(v) for v in rest.split(":"))
        m = list(random_systems(k + 1, s))[-1]
    elif kind == "mutant":
        s, k = (int(v) for v in rest.split(":"))
        m = list(mutants(seeds(corpus), k + 1, s))[-1]
    else:
        path = Path(spec)
        plan = re.search(r"-p(\d+)\.", path.name)
        fmt = _fmt_of(path) or "fcl"
        m = Mutant(0, str(path), fmt, (), _decode(path), int(plan.group(1)) if plan else 0)
    return dataclasses.replace(m, full=True)


def _replay_main(spec: str, corpus: bool) -> int:
    import warnings

    warnings.simplefilter("ignore")
    m = replay(spec, corpus)
    with tempfile.TemporaryDirectory(prefix="fuzzyctl-replay-") as tmp:
        out = run_one(m, Path(tmp))
    print(f"{m.seed}: {out.kind}; compared: {', '.join(sorted(out.compared)) or '-'}")
    if out.detail:
        print(f"    {out.detail}")
    return 1 if out.kind in ("crash", "disagree", "hang", "memory") else 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--mutants", type=int, default=3000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--corpus", action="store_true", help="also mutate the shared real-world corpus")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=30.0, help="CPU seconds per model (default 30)")
    ap.add_argument("--memory", type=int, default=500, help="MB per worker process (default 500)")
    ap.add_argument("--save", type=Path, default=None, help="write failing mutants to this directory")
    ap.add_argument("--systems", type=int, default=0, help="random systems after the mutants (default 0)")
    ap.add_argument("--c-rate", type=float, default=0.1, help="share of loaded models through generated C")
    ap.add_argument("--cli-rate", type=float, default=0.25, help="share of loaded models through the CLI")
    ap.add_argument(
        "--replay", default=None, help="run one model again: a saved file, system:SEED:K, mutant:SEED:N"
    )
    args = ap.parse_args(argv)
    if args.replay:
        return _replay_main(args.replay, args.corpus)
    report = campaign(
        seeds(args.corpus),
        args.mutants,
        args.seed,
        workers=args.workers,
        timeout=args.timeout,
        memory_mb=args.memory,
        save=args.save,
        progress=True,
        n_systems=args.systems,
        rates=(args.c_rate, args.cli_rate),
    )
    print(report.counts_table())
    print(report.summary())
    if report.failures:
        print(report.describe(limit=200))
    return 1 if report.failures else 0


if __name__ == "__main__":
    raise SystemExit(main())
