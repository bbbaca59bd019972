"""The FMU's interface: one FMI variable per block input, output and tunable parameter entry,
and modelDescription.xml / buildDescription.xml for FMI 2.0 and 3.0.

Value references: 0 is ``time``; then the inputs, ``ENABLE``, the outputs, ``INFO``, and one
per entry of each tunable parameter array (term points, singleton positions, weights, ...),
named ``FZ_temp_X[0]``: the C field and its index, as in the ST and C docs (docs/codegen.md).
Every text from the model goes through :mod:`fuzzyctl.escape` (``xml_attr``).
"""

from __future__ import annotations

from dataclasses import dataclass

from fuzzyctl.escape import xml_attr
from fuzzyctl.ir.nodes import Decl, Program

#: The FMI versions ``--fmi`` accepts.
FMI_VERSIONS = (2, 3)


@dataclass(frozen=True)
class Variable:
    """One FMI variable of the FMU.  ``kind``: input, enable, output, info or parameter;
    ``field``/``index``: where it lives in the C struct (``index`` None for a scalar)."""

    name: str
    vr: int
    kind: str
    field: str
    index: int | None = None
    start: float | None = None
    description: str = ""


@dataclass(frozen=True)
class ParamArray:
    """A tunable parameter array of the struct: its value references are ``base .. base+size-1``."""

    field: str
    base: int
    size: int


@dataclass(frozen=True)
class Interface:
    variables: list[Variable]
    arrays: list[ParamArray]

    def of(self, kind: str) -> list[Variable]:
        return [v for v in self.variables if v.kind == kind]

    @property
    def vr_enable(self) -> int:
        return self.of("enable")[0].vr

    @property
    def vr_info(self) -> int:
        return self.of("info")[0].vr


def _entry_descriptions(decl: Decl) -> list[str]:
    """``"temp: term points x (sorted at run time): cold x0"`` per entry, from the comment
    the ST and C generators write above the array (head line, then ``[i] what`` lines)."""
    lines = decl.comment.splitlines()
    head = lines[0] if lines else decl.name
    entries: dict[int, str] = {}
    for line in lines[1:]:
        index, sep, rest = line.partition("]")
        if sep and index.startswith("[") and index[1:].isdigit():
            entries[int(index[1:])] = rest.strip()
    size = decl.size or 1
    return [f"{head}: {entries[i]}" if i in entries else f"{head} [{i}]" for i in range(size)]


def interface(prog: Program) -> Interface:
    """The FMI variables of a generated C program (``build(plan, "c").program``)."""
    out: list[Variable] = []
    arrays: list[ParamArray] = []
    vr = 1
    inputs = [d for d in prog.of("input") if d.name != "ENABLE"]
    outputs = [d for d in prog.of("output") if d.name != "INFO"]
    for d in inputs:
        out.append(Variable(d.name, vr, "input", d.name, start=0.0, description=f"input {d.name}"))
        vr += 1
    enable = prog.decl("ENABLE")
    out.append(Variable("ENABLE", vr, "enable", "ENABLE", description=enable.comment))
    vr += 1
    for d in outputs:
        out.append(Variable(d.name, vr, "output", d.name, description=f"output {d.name}"))
        vr += 1
    out.append(Variable("INFO", vr, "info", "INFO", description=prog.decl("INFO").comment))
    vr += 1
    for d in prog.of("param"):
        values = d.init if isinstance(d.init, tuple) else (float(d.init or 0.0),)
        arrays.append(ParamArray(d.name, vr, len(values)))
        for i, (value, text) in enumerate(zip(values, _entry_descriptions(d), strict=False)):
            out.append(Variable(f"{d.name}[{i}]", vr, "parameter", d.name, i, float(value), text))
            vr += 1
    return Interface(out, arrays)


def _num(x: float) -> str:
    return repr(float(x))


def _attrs(**kw: str | None) -> str:
    return "".join(f' {k}="{xml_attr(v)}"' for k, v in kw.items() if v is not None)


def model_description(
    iface: Interface, *, ident: str, token: str, fmi: int, tool: str, sources: list[str], description: str
) -> str:
    """modelDescription.xml of a co-simulation FMU (``sources``: the C files an importer
    compiles, listed in ``<SourceFiles>`` for FMI 2; FMI 3 lists them in buildDescription.xml)."""
    head = _attrs(
        fmiVersion="2.0" if fmi == 2 else "3.0",
        modelName=ident,
        description=description,
        generationTool=tool,
        **({"guid": token} if fmi == 2 else {"instantiationToken": token}),
        variableNamingConvention="flat",
        **({"numberOfEventIndicators": "0"} if fmi == 2 else {}),
    )
    lines = ['<?xml version="1.0" encoding="UTF-8"?>', f"<fmiModelDescription{head}>"]
    cs = _attrs(modelIdentifier=ident, canHandleVariableCommunicationStepSize="true")
    if fmi == 2:
        cs += ' canNotUseMemoryManagementFunctions="true"'
        cs += ' canGetAndSetFMUstate="true" canSerializeFMUstate="true"'
        lines.append(f"  <CoSimulation{cs}>")
        lines.append("    <SourceFiles>")
        lines += [f"      <File{_attrs(name=s)}/>" for s in sources]
        lines += ["    </SourceFiles>", "  </CoSimulation>"]
    else:
        lines.append(f'  <CoSimulation{cs} canGetAndSetFMUState="true" canSerializeFMUState="true"/>')
    lines += [
        "  <LogCategories>",
        '    <Category name="logEvents" description="Log events"/>',
        '    <Category name="logStatusError" description="Log error messages"/>',
        "  </LogCategories>",
        '  <DefaultExperiment startTime="0"/>',
        "  <ModelVariables>",
    ]
    lines += _variables(iface, fmi)
    lines.append("  </ModelVariables>")
    lines += _structure(iface, fmi)
    lines.append("</fmiModelDescription>")
    return "\n".join(lines) + "\n"


def _variables(iface: Interface, fmi: int) -> list[str]:
    time = _attrs(name="time", valueReference="0", causality="independent", variability="continuous")
    time_desc = _attrs(description="Simulation time")
    out = [
        f"    <ScalarVariable{time}{time_desc}><Real/></ScalarVariable>"
        if fmi == 2
        else f"    <Float64{time}{time_desc}/>"
    ]
    for v in iface.variables:
        causality, variability, start, initial = {
            "input": ("input", "continuous", _num(v.start or 0.0), None),
            "enable": ("input", "discrete", "true", None),
            "output": ("output", "continuous", None, "calculated"),
            "info": ("output", "discrete", None, "calculated"),
            "parameter": ("parameter", "tunable", _num(v.start or 0.0), "exact"),
        }[v.kind]
        common = _attrs(
            name=v.name,
            valueReference=str(v.vr),
            description=v.description or None,
            causality=causality,
            variability=variability,
            initial=initial,
        )
        if fmi == 2:
            elem = {"enable": "Boolean", "info": "Integer"}.get(v.kind, "Real")
            out.append(f"    <ScalarVariable{common}><{elem}{_attrs(start=start)}/></ScalarVariable>")
        else:
            elem = {"enable": "Boolean", "info": "UInt8"}.get(v.kind, "Float64")
            out.append(f"    <{elem}{common}{_attrs(start=start)}/>")
    return out


def _structure(iface: Interface, fmi: int) -> list[str]:
    """Outputs (and INFO) depend on the inputs and ENABLE: direct feedthrough of a static map."""
    unknowns = [v for v in iface.variables if v.kind in ("output", "info")]
    if fmi == 3:
        lines = ["  <ModelStructure>"]
        lines += [f'    <Output valueReference="{v.vr}"/>' for v in unknowns]
        lines += [f'    <InitialUnknown valueReference="{v.vr}"/>' for v in unknowns]
        return [*lines, "  </ModelStructure>"]
    # FMI 2 refers to variables by their 1-based position in ModelVariables (time is 1)
    position = {v.vr: i + 2 for i, v in enumerate(iface.variables)}
    rows = "".join(f'      <Unknown index="{position[v.vr]}"/>\n' for v in unknowns).rstrip("\n")
    return [
        "  <ModelStructure>",
        "    <Outputs>",
        rows,
        "    </Outputs>",
        "    <InitialUnknowns>",
        rows,
        "    </InitialUnknowns>",
        "  </ModelStructure>",
    ]


def build_description(ident: str, sources: list[str]) -> str:
    """buildDescription.xml (FMI 3): how to compile ``sources/``."""
    files = "".join(f"      <SourceFile{_attrs(name=s)}/>\n" for s in sources)
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<fmiBuildDescription fmiVersion="3.0">\n'
        f"  <BuildConfiguration{_attrs(modelIdentifier=ident)}>\n"
        '    <SourceFileSet language="C99">\n'
        f"{files}"
        '      <PreprocessorDefinition name="FMI_VERSION" value="3"/>\n'
        '      <IncludeDirectory name="."/>\n'
        "    </SourceFileSet>\n"
        "  </BuildConfiguration>\n"
        "</fmiBuildDescription>\n"
    )
