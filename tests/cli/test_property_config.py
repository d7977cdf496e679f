"""Property-based tests (hypothesis) of the config parsers: any value in any field of a valid
HCS or Couette config, and any bytes as a config file, give a validated config or a one-line
InputError — never another exception, never a non-finite value in an accepted config (issue 11).
"""

from __future__ import annotations

import copy
import itertools
import math
import tomllib
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ktgf.errors import InputError
from ktgf.io import read_toml

FAST = settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                        HealthCheck.function_scoped_fixture])
LONG = settings(max_examples=2000, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                         HealthCheck.function_scoped_fixture])
ROOT = Path(__file__).resolve().parents[2]
HCS = tomllib.loads((ROOT / "examples" / "hcs_3d.toml").read_text())
COUETTE = tomllib.loads((ROOT / "examples" / "couette_planar.toml").read_text())

#: values a TOML file can hold, and a few it cannot (from Python callers)
VALUE = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True), st.integers(-(2**70), 2**70), st.booleans(),
    st.text(max_size=8), st.sampled_from(["ret", "mode", "random", "none", "tau", "s", "haff", "float32", "planar",
                                          "annular", "johnson-jackson", "x.nc", ".", ""]),
    st.lists(st.one_of(st.integers(-3, 70), st.floats(-1, 100)), max_size=4), st.none(), st.dictionaries(
        st.sampled_from(["a", "kind", "gap"]), st.integers(0, 3), max_size=2),
)


pytestmark = pytest.mark.contract


def _leaves(d: dict, prefix: tuple = ()) -> list[tuple]:
    out = []
    for k, v in d.items():
        out += _leaves(v, (*prefix, k)) if isinstance(v, dict) else [(*prefix, k)]
    return out


def _mutate(base: dict, path: tuple, value) -> dict:
    data = copy.deepcopy(base)
    node = data
    for k in path[:-1]:
        if not isinstance(node.get(k), dict):
            node[k] = {}
        node = node[k]
    if value is _DELETE:
        node.pop(path[-1], None)
    else:
        node[path[-1]] = value
    return data


_DELETE = object()
HCS_PATHS = _leaves(HCS) + [("initial", "mode"), ("initial", "kind"), ("grid", "length"), ("grid", "length_d"),
                            ("numerics", "phi_stop"), ("time", "max_steps_per_call"), ("extra",), ("model", "options")]
COUETTE_PATHS = _leaves(COUETTE) + [("model_options",), ("numerics", "tol"), ("geometry", "omega"), ("walls", "top")]


def _finite_leaves(x) -> bool:
    if isinstance(x, dict):
        return all(_finite_leaves(v) for v in x.values())
    if isinstance(x, list):
        return all(_finite_leaves(v) for v in x)
    return not (isinstance(x, float) and not math.isfinite(x))


def _or_input_error(fn, *args):
    """``fn(*args)``, or None if it raised a one-line InputError (any other exception fails the test)."""
    try:
        return fn(*args)
    except InputError as exc:
        assert "\n" not in str(exc)
        return None


def _parsed(parse, base: dict, changes: list):
    data = base
    for path, value in changes:
        data = _mutate(data, path, value)
    cfg = _or_input_error(parse, data)
    if cfg is not None:
        assert _finite_leaves(cfg.model_dump(mode="python"))
    return cfg


def _hcs_case(changes: list) -> None:
    from ktgf.solver.config import parse_config
    from ktgf.solver.run import Simulation

    cfg = _parsed(parse_config, HCS, changes)
    if cfg is None:
        return
    assert not isinstance(cfg.model.restitution, bool) and 0 < cfg.model.restitution <= 1
    sim = _or_input_error(Simulation, cfg)  # box, output times, memory check: nothing compiled or allocated
    if sim is not None:
        t = sim.output_times
        assert all(math.isfinite(x) for x in t) and all(b > a for a, b in itertools.pairwise(t))


def _couette_case(changes: list) -> None:
    from ktgf.couette.config import parse_config

    cfg = _parsed(parse_config, COUETTE, changes)
    if cfg is not None:
        assert not isinstance(cfg.restitution, bool)
        assert cfg.output.path.endswith(".nc") and Path(cfg.output.path).name not in ("", ".", "..")


CHANGES_HCS = st.lists(st.tuples(st.sampled_from(HCS_PATHS), st.one_of(VALUE, st.just(_DELETE))), min_size=1,
                       max_size=3)
CHANGES_COUETTE = st.lists(st.tuples(st.sampled_from(COUETTE_PATHS), st.one_of(VALUE, st.just(_DELETE))),
                           min_size=1, max_size=3)


@FAST
@given(CHANGES_HCS)
def test_hcs_config_fields(changes: list) -> None:
    _hcs_case(changes)


@FAST
@given(CHANGES_COUETTE)
def test_couette_config_fields(changes: list) -> None:
    _couette_case(changes)


@FAST
@given(st.one_of(st.binary(max_size=200), st.text(max_size=200).map(lambda s: s.encode("utf-8")),
                 st.text(max_size=50).map(lambda s: s.encode("utf-16")),
                 st.text(alphabet="é°ü±", max_size=20).map(lambda s: ("a = 1\n" + s).encode("latin-1"))))
def test_any_bytes_as_a_config_file(tmp_path_factory, raw: bytes) -> None:
    p = tmp_path_factory.mktemp("cfg") / "c.toml"
    p.write_bytes(raw)
    try:
        data = read_toml(p)
    except InputError as exc:
        assert "\n" not in str(exc)
        return
    assert isinstance(data, dict)


@pytest.mark.slow
@LONG
@given(CHANGES_HCS, CHANGES_COUETTE)
def test_long_fuzz_of_both_parsers(hcs: list, couette: list) -> None:
    _hcs_case(hcs)
    _couette_case(couette)
