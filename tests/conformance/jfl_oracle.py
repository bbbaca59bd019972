"""The live jFuzzyLogic 3.3 oracle (extra suite ``jfl_oracle``, ../shared/tools/jfuzzylogic).

One JVM runs many (model, rows) jobs: ``tests/conformance/jfl/JflBatch.java`` does for each
job what the oracle's own driver (``jfl MODEL INPUTS``) does - it calls that driver's loader -
and is compiled once into ``~/.cache/fuzzyctl-tests/jfl/<hash>`` (keyed by its source and the
oracle jar).  Without ``javac`` each job runs through ``jfl`` itself (slower, same answers).
``run(jobs, cache=True)`` (the fixed sets: the corpus, the seed-0 systems) keeps each job's
answer under ``~/.cache/fuzzyctl-tests/jfl/answers/``, keyed by the job (model text, rows,
outputs), JflBatch.java and the oracle jar: jFuzzyLogic is deterministic, so a cached answer
is the answer it gave to that very question.  Fresh random systems always ask it live.

``libm``: Java's ``Math.exp``, ``cos`` and ``pow`` are, on x86-64 HotSpot, Intel intrinsics
(``"intrinsic"``); with ``-XX:-UseLibmIntrinsic`` they are fdlibm's, the ``StrictMath`` that
Java specifies (``"fdlibm"``, the default here, what the jfuzzylogic profile computes).  The
two differ in the last bit on a few percent of arguments, which moves jFuzzyLogic's own MM, LM,
RM and COA by a sample step on a tie (docs/engine.md).
"""

from __future__ import annotations

import hashlib
import math
import os
import shutil
import subprocess
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from tests import diskcache
from tests.extras import extra_path

HERE = Path(__file__).resolve().parent / "jfl"
TOOLS = extra_path("jfl_oracle", "tools", "jfuzzylogic")
JARS = ("jfuzzylogic-3.3-oracle.jar", "antlrworks-1.2.jar")
CACHE = diskcache.CACHE / "jfl"  # $FUZZYCTL_TEST_CACHE or ~/.cache/fuzzyctl-tests
#: JVM options per choice of Java's math library (see the module's doc)
LIBM = {"fdlibm": ("-XX:+UnlockDiagnosticVMOptions", "-XX:-UseLibmIntrinsic"), "intrinsic": ()}


@dataclass
class Job:
    """One model (FCL text, or a file given as its path) and the rows to evaluate in order on
    one function block (``rows`` maps input names to values; ``all_inputs``: one evaluation
    with every input at that value)."""

    fcl: str | Path
    rows: list[dict[str, float]] = field(default_factory=list)
    outputs: list[str] | None = None
    all_inputs: float | None = None


@dataclass
class Answer:
    load_error: str | None
    syntax_errors: int = 0
    outputs: list[str] = field(default_factory=list)
    #: per row, per output: a float (nan included) or the "ERR:<message>" text
    rows: list[list[float | str]] = field(default_factory=list)

    @property
    def clean(self) -> bool:
        """Loaded with no syntax error (jFuzzyLogic silently recovers from those)."""
        return self.load_error is None and self.syntax_errors == 0


def _classpath() -> str | None:
    javac = shutil.which("javac")
    if javac is None:
        return None
    source = (HERE / "JflBatch.java").read_bytes()
    jar = TOOLS / JARS[0]
    key = hashlib.sha1(source + str(jar.stat().st_size).encode() + str(jar.stat().st_mtime_ns).encode())
    out = CACHE / key.hexdigest()[:16]
    if not (out / "JflBatch.class").exists():
        out.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(dir=out.parent))
        subprocess.run(
            [javac, "-nowarn", "-source", "8", "-target", "8", "-cp", _jars(), "-d", str(tmp),
             str(HERE / "JflBatch.java")],
            check=True, capture_output=True,
        )  # fmt: skip
        for f in tmp.iterdir():
            os.replace(f, out / f.name)
        tmp.rmdir()
    return f"{_jars()}{os.pathsep}{out}"


def _jars() -> str:
    return os.pathsep.join(str(TOOLS / j) for j in JARS)


def run(jobs: list[Job], cache: bool = False, libm: str = "fdlibm") -> list[Answer]:
    """Ask jFuzzyLogic; one answer per job, in order (``cache``, ``libm``: see the module's
    doc)."""
    if not cache:
        return [_parse(body) for body in _ask(jobs, libm)]
    keys = [_key(job, libm) for job in jobs]
    bodies: list[str | None] = [
        (CACHE / "answers" / k).read_text(encoding="utf-8") if (CACHE / "answers" / k).exists() else None
        for k in keys
    ]
    missing = [i for i, b in enumerate(bodies) if b is None]
    if missing:
        (CACHE / "answers").mkdir(parents=True, exist_ok=True)
        for i, body in zip(missing, _ask([jobs[i] for i in missing], libm), strict=True):
            bodies[i] = body
            tmp = CACHE / "answers" / f"{keys[i]}.{os.getpid()}"
            tmp.write_text(body, encoding="utf-8")
            os.replace(tmp, CACHE / "answers" / keys[i])  # atomic: parallel workers
    return [_parse(b) for b in bodies if b is not None]


def _key(job: Job, libm: str) -> str:
    jar = TOOLS / JARS[0]
    model = job.fcl.read_bytes() if isinstance(job.fcl, Path) else job.fcl.encode()
    h = hashlib.sha1((HERE / "JflBatch.java").read_bytes())
    h.update(f"{jar.stat().st_size}:{jar.stat().st_mtime_ns}:{libm}\0".encode())
    h.update(model + b"\0" + _csv(job).encode() + b"\0" + ",".join(job.outputs or ["-"]).encode())
    return h.hexdigest()


def _ask(jobs: list[Job], libm: str) -> list[str]:
    """jFuzzyLogic's raw answer to each job."""
    with tempfile.TemporaryDirectory(prefix="fuzzyctl-jfl-") as tmp:
        d = Path(tmp)
        lines = []
        for i, job in enumerate(jobs):
            if isinstance(job.fcl, Path):
                model = job.fcl
            else:
                model = d / f"m{i}.fcl"
                model.write_text(job.fcl, encoding="utf-8")
            csv = d / f"m{i}.csv"
            csv.write_text(_csv(job), encoding="utf-8")
            lines.append(f"{model}\t{csv}\t{','.join(job.outputs) if job.outputs else '-'}")
        cp = _classpath()
        if cp is not None:
            (d / "jobs.txt").write_text("\n".join(lines) + "\n", encoding="utf-8")
            got = subprocess.run(
                ["java", "-Xshare:auto", "-XX:+UseSerialGC", "-XX:TieredStopAtLevel=1", *LIBM[libm],
                 "-cp", cp, "JflBatch", str(d / "jobs.txt")],
                check=True, capture_output=True, text=True,
            ).stdout  # fmt: skip
            chunks = got.split("## job ")[1:]
        else:  # no javac: the oracle's own driver, once per job
            chunks = []
            for i, line in enumerate(lines):
                model, csv, outs = line.split("\t")
                args = [str(TOOLS / "jfl"), model, csv] + (["--outputs", outs] if outs != "-" else [])
                env = {**os.environ, "JAVA_TOOL_OPTIONS": " ".join(LIBM[libm])}
                res = subprocess.run(args, capture_output=True, text=True, env=env)
                body = "\n".join(ln for ln in res.stdout.splitlines() if not ln.startswith("# fb="))
                chunks.append(f"{i}\n{body}")
    assert len(chunks) == len(jobs), got if cp is not None else chunks
    return [c.partition("\n")[2] for c in chunks]


def _csv(job: Job) -> str:
    if job.all_inputs is not None:
        return f"*={job.all_inputs!r}\n"
    names = list(job.rows[0]) if job.rows else ["_"]
    body = [",".join(repr(float(r[n])) for n in names) for r in job.rows]
    return "\n".join([",".join(names), *body]) + "\n"


def _parse(body: str) -> Answer:
    lines = body.splitlines()
    if lines and lines[0].startswith("# LOAD_ERROR"):
        return Answer(lines[0][len("# LOAD_ERROR ") :])
    syntax = int(lines[0].split("=", 1)[1])
    rest = [ln for ln in lines[1:] if not ln.startswith("#")]
    outputs = rest[0].split(",") if rest and rest[0] else []
    rows: list[list[float | str]] = []
    for ln in rest[1:]:
        cells = ln.split(",") if outputs else []
        rows.append([c if c.startswith("ERR:") else _float(c) for c in cells])
    return Answer(None, syntax, outputs, rows)


def _float(text: str) -> float:
    if text == "nan":
        return math.nan
    if text in ("inf", "-inf"):
        return math.inf if text == "inf" else -math.inf
    return float(text)
