"""Configuration errors name the file, the table and the key; everything wrong is reported
at once; addresses are checked by the protocol of the connection they use."""

from __future__ import annotations

from pathlib import Path

import pytest

from fuzzyctl.runtime import ConfigError, Runtime, load_config, parse_config
from tests.conftest import EXAMPLES
from tests.runtime.helpers import FPLTEST_FCL


def problems(text: str, path: str = "plant.toml") -> list[str]:
    with pytest.raises(ConfigError) as info:
        parse_config(text, path)
    return info.value.problems


def test_every_problem_names_file_table_and_key() -> None:
    found = problems(
        f"""
[runtime]
spin = -1

[connections.plc]
type = "modbus"
port = 70000
colour = "red"

[connections.cpu]
type = "profinet"

[instances.tank]
knowledge_base = "{FPLTEST_FCL}"
period = 0.0001

[instances.pump]
knowledge_base = "{FPLTEST_FCL}"
period = 0.01
hold_time = 2

[instances.pump.inputs]
Temp = {{ connection = "plc", address = -3 }}
Pressure = {{ connection = "nowhere", address = 2 }}

[instances.pump.outputs]
Valve = {{ connection = "plc", address = 4, safe = "closed" }}
"""
    )
    text = "\n".join(found)
    assert "plant.toml: [runtime] spin: Input should be greater than or equal to 0" in text
    assert "plant.toml: [connections.plc] port: Input should be less than or equal to 65535" in text
    assert "plant.toml: [connections.plc] colour: unknown key" in text
    assert "plant.toml: [connections.cpu] type: unknown connection type 'profinet'" in text
    assert "plant.toml: [instances.tank] period: Input should be greater than or equal to 0.001" in text
    assert (
        "plant.toml: [instances.pump.inputs.Temp] address: Input should be greater than or equal to 0" in text
    )
    assert "plant.toml: [instances.pump.inputs.Pressure] connection: no connection 'nowhere' (plc)" in text
    assert "plant.toml: [instances.pump.outputs.Valve] safe: a safe value is a finite number" in text
    assert len(found) == 8


def test_toml_syntax_errors_and_missing_tables() -> None:
    assert problems("[instances\n")[0].startswith("plant.toml: not valid TOML:")
    assert problems("")[0] == "plant.toml: no [instances.<name>] table: nothing to run"
    assert (
        "[instances.x] knowledge_base: required key is missing" in problems("[instances.x]\nperiod = 1\n")[0]
    )
    bad_s7 = problems(
        '[connections.c]\ntype = "s7"\n[instances.x]\nknowledge_base = "a.fcl"\nperiod = 1\n'
        '[instances.x.inputs]\nT = { connection = "c", db = 0, offset = 0, table = "holding" }\n'
    )
    assert any("[instances.x.inputs.T] db: Input should be greater than or equal to 1" in p for p in bad_s7)
    assert any("[instances.x.inputs.T] table: unknown key" in p for p in bad_s7)


def test_names_are_checked_against_the_knowledge_base(tmp_path: Path) -> None:
    path = tmp_path / "plant.toml"
    path.write_text(
        f"""
[connections.mb]
type = "modbus-server"
port = 0

[instances.valve]
knowledge_base = "{FPLTEST_FCL}"
period = 0.01
params = {{ START_STOP = 70000, MAN_AUTO = 1 }}

[instances.valve.inputs]
Tmp = {{ connection = "mb", address = 0 }}

[instances.valve.outputs]
Valve = {{ connection = "mb", address = 0 }}

[instances.broken]
knowledge_base = "{tmp_path / "missing.fcl"}"
period = 0.01
"""
    )
    with pytest.raises(ConfigError) as info:
        Runtime(load_config(path), api=False, event_log=None)
    text = "\n".join(info.value.problems)
    assert f"{path}: [instances.valve.params] START_STOP: START_STOP = 70000.0" in text
    assert f"{path}: [instances.valve.params] MAN_AUTO: 'MAN_AUTO' is not a parameter" in text
    assert (
        f"{path}: [instances.valve.inputs] Tmp: 'Tmp' is not an input of this block (Temp, Pressure" in text
    )
    assert f"{path}: [instances.broken] knowledge_base:" in text and "cannot read" in text


def test_a_point_written_twice_is_refused(tmp_path: Path) -> None:
    text = f"""
[connections.mb]
type = "modbus-server"
port = 0
[instances.a]
knowledge_base = "{FPLTEST_FCL}"
period = 0.01
[instances.a.outputs]
Valve = {{ connection = "mb", address = 10 }}
[instances.b]
knowledge_base = "{FPLTEST_FCL}"
period = 0.01
[instances.b.outputs]
Valve = {{ connection = "mb", address = 10 }}
"""
    with pytest.raises(
        ConfigError, match=r"\[instances.b.outputs\] Valve: holding 10..11 float32 on mb is written"
    ):
        Runtime(parse_config(text, tmp_path / "p.toml"), api=False, event_log=None)


@pytest.mark.parametrize("name", sorted(p.name for p in (EXAMPLES / "serve").glob("*.toml")))
def test_example_configurations_load_and_build(name: str) -> None:
    rt = Runtime(load_config(EXAMPLES / "serve" / name), api=False, event_log=None)
    assert rt.instances
    rt.stop()
