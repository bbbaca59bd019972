"""Generated Structured Text: both independent parsers accept it, it keeps to the portable
subset, and executed by a small interpreter on blark's parse tree it computes what the engine
computes - REAL emulated in float32: within 1e-4 of each output's range on 1000 random inputs
(inside the inputs' physical ranges, as float32 values) per example; LREAL within 1e-9.

blark's Earley parser needs ~12 ms per line, so each distinct text is parsed once, in worker
processes; the dialect and precision variants are checked to be token-identical to a parsed
text apart from their dialect keywords."""

from __future__ import annotations

import re
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
import pytest
import tree_sitter_iec61131_3_st as ts_st
from tree_sitter import Language, Parser

import fuzzyctl
from fuzzyctl.codegen import CodegenError, generate_st
from tests.codegen import systems as S
from tests.codegen.st_interp import STBlock, Translation, translate

EXAMPLES = S.example_files()
PARSER = Parser(Language(ts_st.language()))


def st(path: Path, dialect: str = "codesys", lreal: bool = False) -> str:
    return generate_st(S.load(path), dialect=dialect, lreal=lreal)


@pytest.fixture(scope="module")
def parsed() -> dict[tuple[str, bool | str], Translation]:
    """blark's parse of every example (REAL) and of figure 7 in LREAL, in two worker
    processes.  The TwinCAT and SCL texts are token for token these texts (SCL once its
    conventions are undone: test_variants_are_the_parsed_program), so this covers them."""
    fig7 = S.EXAMPLES / "figure7.fcl"
    jobs: list[tuple[tuple[str, bool | str], str]] = [((p.name, False), st(p)) for p in EXAMPLES]
    jobs += [(("figure7.fcl", True), st(fig7, lreal=True))]
    jobs.sort(key=lambda j: -len(j[1]))  # longest first: the two workers finish together
    with ProcessPoolExecutor(max_workers=2) as pool:
        results = list(pool.map(translate, [text for _k, text in jobs]))
    return {key: tr for (key, _t), tr in zip(jobs, results, strict=True)}


def tree_sitter_errors(text: str) -> list[tuple[int, str]]:
    tree = PARSER.parse(text.encode())
    bad: list[tuple[int, str]] = []

    def walk(n) -> None:  # type: ignore[no-untyped-def]
        if n.type == "ERROR" or n.is_missing:
            bad.append((n.start_point[0] + 1, text.splitlines()[n.start_point[0]]))
        for ch in n.children:
            walk(ch)

    walk(tree.root_node)
    return bad


def scl_to_iec(text: str) -> str:
    """Undo exactly the SCL conventions: '#' before variables, REGION lines, VERSION, the
    attribute block, BEGIN and the quoted block name."""
    out = []
    for line in text.splitlines():
        s = line.strip()
        if s.startswith(("REGION ", "END_REGION", "VERSION :", "{ S7_Optimized_Access")) or s == "BEGIN":
            continue
        out.append(re.sub(r'FUNCTION_BLOCK "(\w+)"', r"FUNCTION_BLOCK \1", line.replace("#", "")))
    return "\n".join(out) + "\n"


def tokens(text: str) -> list[str]:
    """The tokens of a text without comments."""
    text = re.sub(r"\(\*.*?\*\)", " ", text, flags=re.S)
    return re.findall(r"\d+\.\d+(?:E[+-]?\d+)?|16#[0-9A-F]+|\w+|:=|<>|<=|>=|\.\.|\S", text)


# --------------------------------------------------------------------------- parsers


def test_blark_parses_every_example_and_figure7_in_lreal(
    parsed: dict[tuple[str, bool | str], Translation],
) -> None:
    assert {name for name, _v in parsed} == {p.name for p in EXAMPLES}
    assert {v for name, v in parsed if name == "figure7.fcl"} == {False, True}
    for tr in parsed.values():
        assert tr.source.startswith("def _step")


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_tree_sitter_accepts_every_dialect_and_precision(path: Path) -> None:
    for dialect in ("codesys", "twincat", "scl", "iec"):
        for lreal in (False, True):
            text = st(path, dialect, lreal)
            check = scl_to_iec(text) if dialect == "scl" else text
            assert tree_sitter_errors(check) == [], (dialect, lreal)


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_variants_are_the_parsed_program(path: Path) -> None:
    """TwinCAT text = CODESYS text; LREAL = REAL with the type names changed; SCL = the same
    tokens once its conventions are undone - so blark's parse of one covers all."""
    base = st(path)
    assert tokens(st(path, "twincat")) == tokens(base)
    real_tokens = tokens(base)
    lreal = [
        t.replace("INT_TO_LREAL", "INT_TO_REAL").replace("LREAL", "REAL")
        for t in tokens(st(path, lreal=True))
    ]
    assert lreal == real_tokens
    scl = st(path, "scl")
    assert "VERSION : 0.1" in scl and "REGION " in scl and "\nBEGIN\n" in scl
    assert re.search(r"#FZ_\w+ :=", scl) and re.search(r"#INFO :=", scl)
    # the same statements; the same declarations, the scratch arrays in VAR_TEMP (SCL) or
    # in a VAR block of their own (the others: matiec refuses uninitialised VAR_TEMP arrays)
    scl_decls, scl_body = _split(scl_to_iec(scl))
    decls, body = _split(base)
    assert tokens(scl_body) == tokens(body)
    assert _declarations(scl_decls) == _declarations(decls)
    scl_temp = re.search(r"VAR_TEMP\n(.*?)END_VAR", scl_decls, flags=re.S)
    temp = re.search(r"VAR_TEMP\n(.*?)END_VAR", decls, flags=re.S)
    assert scl_temp and "ARRAY" in scl_temp.group(1)
    assert temp is None or "ARRAY" not in temp.group(1)


def _split(text: str) -> tuple[str, str]:
    cut = text.rindex("END_VAR") + len("END_VAR")
    return text[:cut], text[cut:]


def _declarations(text: str) -> list[str]:
    """The declaration lines of a block, comments dropped, in sorted order."""
    code = re.sub(r"\(\*.*?\*\)", " ", text, flags=re.S)
    return sorted(" ".join(line.split()) for line in code.splitlines() if " : " in line)


def test_tree_sitter_accepts_every_st_expressible_conformance_system() -> None:
    checked = 0
    for rel, p in S.conformance_files():
        try:
            text = generate_st(S.load(p))
        except CodegenError:
            continue
        assert tree_sitter_errors(text) == [], rel
        checked += 1
    assert checked >= 30


# --------------------------------------------------------------------------- the portable subset


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_portable_subset(path: Path) -> None:
    text = st(path)
    code = re.sub(r"\(\*.*?\*\)", " ", text, flags=re.S)
    assert "**" not in code and "//" not in code
    for fn in ("MIN", "MAX", "LIMIT", "EXPT", "SEL", "MUX"):
        assert not re.search(rf"\b{fn}\s*\(", code), fn
    words = set(re.findall(r"[A-Za-z_]\w*", code))
    keywords = {
        "IF",
        "THEN",
        "ELSIF",
        "ELSE",
        "END_IF",
        "FOR",
        "TO",
        "BY",
        "DO",
        "END_FOR",
        "WHILE",
        "END_WHILE",
        "AND",
        "OR",
        "NOT",
        "VAR",
        "VAR_INPUT",
        "VAR_OUTPUT",
        "VAR_TEMP",
        "END_VAR",
        "ARRAY",
        "OF",
        "REAL",
        "INT",
        "BOOL",
        "BYTE",
        "TRUE",
        "FALSE",
        "FUNCTION_BLOCK",
        "END_FUNCTION_BLOCK",
    }
    for w in words:
        if w.upper() in keywords:
            assert w == w.upper(), w
        assert len(w) <= 24, w
    for lo, hi in re.findall(r"ARRAY\[(\S+?)\.\.(\S+?)\]", code):
        assert lo.isdigit() and hi.isdigit()
    declared = dict(re.findall(r"^\s*(\w+) : (\w+)", code, flags=re.M))
    for counter in re.findall(r"\bFOR (\w+) :=", code):
        assert declared[counter] == "INT"
    fb = fuzzyctl.compile(S.load(path)).plan
    inputs = re.search(r"VAR_INPUT(.*?)END_VAR", code, flags=re.S)
    outputs = re.search(r"VAR_OUTPUT(.*?)END_VAR", code, flags=re.S)
    assert inputs and outputs
    assert re.findall(r"(\w+) : (\w+)", inputs.group(1)) == [(i.name, "REAL") for i in fb.inputs] + [
        ("ENABLE", "BOOL")
    ]
    assert re.findall(r"(\w+) : (\w+)", outputs.group(1)) == [
        (o.name, "REAL") for o in fb.outputs if o.is_output
    ] + [("INFO", "BYTE")]


# --------------------------------------------------------------------------- execution


def _run(block: STBlock, plan: fuzzyctl.engine.plan.Plan, data: np.ndarray) -> np.ndarray:
    names = [o.name.upper() for o in plan.outputs if o.is_output]
    rows = []
    for row in data:
        out = block.step({inp.name: float(v) for inp, v in zip(plan.inputs, row, strict=True)})
        rows.append([float(out[n]) for n in names])
    return np.array(rows, dtype=np.float64).reshape(len(data), len(names))


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_real_execution_matches_the_engine(
    path: Path, parsed: dict[tuple[str, bool | str], Translation]
) -> None:
    plan = S.plan_of(path)
    block = STBlock(parsed[(path.name, False)])
    assert block.real == "REAL"
    data = S.random_inputs(plan, 1000, seed=11, single=True)
    err = S.max_error(plan, _run(block, plan, data), S.reference(plan, data))
    assert err <= 1e-4, err
    print(f"\n{path.name}: REAL worst deviation {err:.2e} of the range")


def test_lreal_execution_matches_the_engine(parsed: dict[tuple[str, bool | str], Translation]) -> None:
    path = S.EXAMPLES / "figure7.fcl"
    plan = S.plan_of(path)
    block = STBlock(parsed[(path.name, True)])
    assert block.real == "LREAL"
    data = S.random_inputs(plan, 1000, seed=12)
    assert S.max_error(plan, _run(block, plan, data), S.reference(plan, data)) <= 1e-9


def test_parameters_can_be_tuned_online(parsed: dict[tuple[str, bool | str], Translation]) -> None:
    """Changing a parameter array in the running instance = compiling the changed FCL."""
    path = S.EXAMPLES / "heater_extension.fcl"
    block = STBlock(parsed[(path.name, False)])
    text = path.read_text()
    # power.high starts at 40: move it to 50 online, and in the source
    xs = block.state["FZ_POWER_X"]
    k = [float(v) for v in xs].index(40.0)
    xs[k] = np.float32(50.0)
    tuned = fuzzyctl.compile(fuzzyctl.load(text.replace("TERM high := (40, 0)", "TERM high := (50, 0)")))
    weights = block.state["FZ_W"]  # rule 5's WITH 0.8 -> 0.3
    assert float(weights[0]) == pytest.approx(0.8)
    weights[0] = np.float32(0.3)
    tuned = fuzzyctl.compile(
        fuzzyctl.load(
            text.replace("TERM high := (40, 0)", "TERM high := (50, 0)").replace("WITH 0.8", "WITH 0.3")
        )
    )
    rng = np.random.default_rng(5)
    for _ in range(200):
        inp = {
            "temp": float(np.float32(rng.uniform(0, 40))),
            "trend": float(np.float32(rng.uniform(-2, 2))),
            "setpoint": float(np.float32(rng.uniform(17, 24))),
            "eco": float(np.float32(rng.uniform(0, 1))),
        }
        got = block.step(inp)
        want = tuned.evaluate(inp)
        assert float(got["POWER"]) == pytest.approx(want["power"], abs=1e-4 * 100)
        assert float(got["FAN"]) == pytest.approx(want["fan"], abs=1e-4 * 100)


def test_info_codes_enable_and_nc(parsed: dict[tuple[str, bool | str], Translation]) -> None:
    block = STBlock(parsed[("heater_extension.fcl", False)])
    fig7 = STBlock(parsed[("figure7.fcl", False)])
    assert fig7.step({"temp": 10.0, "pressure": 60.0})["INFO"] == 0  # every output fired
    ok = {"temp": 15.0, "trend": -1.5, "setpoint": 21.0, "eco": 0.5}
    first = block.step(ok)
    # nothing concludes fan (rules 5, 6 both 0): fan keeps its value (NC), INFO 16#02
    cold_rising = {"temp": 0.0, "trend": 2.0, "setpoint": 21.0, "eco": 0.5}
    out = block.step(cold_rising)
    assert out["INFO"] == 2 and float(out["FAN"]) == float(first["FAN"])
    # a degree input outside 0..1: 16#31, outputs unchanged
    out2 = block.step({**ok, "eco": 1.5})
    assert out2["INFO"] == 0x31 and float(out2["POWER"]) == float(out["POWER"])
    # ENABLE = FALSE: 16#01, outputs unchanged
    block.state["ENABLE"] = False
    out3 = block.step(ok)
    assert out3["INFO"] == 1 and float(out3["POWER"]) == float(out["POWER"])


# --------------------------------------------------------------------------- refusals


def test_refusals_name_the_element(tmp_path: Path) -> None:
    nan_default = next(p for rel, p in S.conformance_files() if rel == "fuzzylite/mamdani/SimpleDimmer.fcl")
    with pytest.raises(CodegenError, match=r"DEFAULT := nan.*Structured Text"):
        generate_st(S.load(nan_default))
    src = (S.EXAMPLES / "figure7.fcl").read_text()
    with pytest.raises(CodegenError, match=r"variable 'exp' is a reserved word"):
        generate_st(fuzzyctl.load(src.replace("temp", "exp")))
    long = "a_very_long_variable_name_x"
    with pytest.raises(CodegenError, match=r"longer than 24"):
        generate_st(fuzzyctl.load(src.replace("pressure", long)))
    with pytest.raises(CodegenError, match=r"unknown dialect"):
        generate_st(fuzzyctl.load(src), dialect="s5")


def test_the_package_never_imports_the_test_parsers() -> None:
    """blark (GPL) and tree-sitter check the output in tests only."""
    from tests.conftest import ROOT

    pattern = re.compile(r"^\s*(?:import|from)\s+(?:blark|tree_sitter)\b", re.M)
    sources = list((ROOT / "src" / "fuzzyctl").rglob("*.py"))
    assert len(sources) > 50
    assert [str(p) for p in sources if pattern.search(p.read_text())] == []
