"""Property-based tests (hypothesis) of the command line: whatever the options, ``ktgf`` answers
with a result (exit 0, strict JSON without NaN) or a one-line error (exit 2) — never a traceback
(issue 11).  Bounded for CI; ``-m slow`` runs the long fuzz.
"""

from __future__ import annotations

import json
import math

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from ktgf.cli import app

FAST = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                       HealthCheck.function_scoped_fixture])
LONG = settings(max_examples=2000, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                         HealthCheck.function_scoped_fixture])

MODELS = st.sampled_from(["ret", "enskog", "visc-div", "proposed", "ret,enskog", "nonsense", "", ",", " ret "])
SPECIAL = st.sampled_from(["", ",", " ", "nan", "inf", "-inf", "1e309", "-0", "0", "1", "abc", "0:1:3", "0.1:0.5:0",
                           "0.1:0.5:-2", "1:2", "0.2,", ",0.3", "0.1:0.4:1e3", "0:0.5:100000000000", "0.3;0.4"])


pytestmark = pytest.mark.contract


def _num_text(x: float) -> str:
    return repr(x)


NUMBER = st.one_of(st.floats(allow_nan=True, allow_infinity=True).map(_num_text),
                   st.floats(0.0, 1.0).map(_num_text), st.integers(-5, 10**7).map(str), SPECIAL)
VALUES = st.one_of(NUMBER, st.lists(st.floats(-0.5, 1.5).map(_num_text), min_size=1, max_size=4).map(",".join),
                   st.tuples(st.floats(-0.2, 1.2), st.floats(-0.2, 1.2), st.integers(-2, 40)).map(
                       lambda t: f"{t[0]!r}:{t[1]!r}:{t[2]}"))


def _no_nan(x) -> None:
    if isinstance(x, dict):
        for v in x.values():
            _no_nan(v)
    elif isinstance(x, list):
        for v in x:
            _no_nan(v)
    else:
        assert x is not None, "NaN in the output"
        assert not (isinstance(x, float) and not math.isfinite(x))


def _reject_constant(name: str):
    raise AssertionError(f"non-standard JSON constant {name}")


def _check(args: list[str]) -> None:
    res = CliRunner().invoke(app, args)
    assert res.exception is None or isinstance(res.exception, SystemExit), (args, repr(res.exception))
    assert res.exit_code in (0, 2), (args, res.exit_code, res.output)
    if res.exit_code == 2:
        err = res.stderr.strip()
        if "Usage:" in err:  # click refused the option text itself (e.g. --n 1.5): a usage box
            assert "Invalid value" in err or "Missing" in err or "No such" in err, err
        else:
            assert len(err.splitlines()) == 1 and err.startswith("Error: "), (args, err)
    elif "json" in args:
        _no_nan(json.loads(res.stdout, parse_constant=_reject_constant))


def _stability_args(model, phi, e, box) -> list[str]:
    args = ["hcs", "stability", "--model", model, "--phi", phi, "--e", e, "--format", "json"]
    return args + (["--box", box] if box is not None else [])


@FAST
@given(MODELS, VALUES, VALUES, st.one_of(st.none(), NUMBER))
def test_hcs_stability(model: str, phi: str, e: str, box: str | None) -> None:
    _check(_stability_args(model, phi, e, box))


def _haff_args(phi, e, theta0, d, n) -> list[str]:
    return ["hcs", "haff", "--model", "ret", "--phi", phi, "--e", e, "--theta0", theta0, "--d", d, "--n", n,
            "--format", "json"]


@FAST
@given(NUMBER, NUMBER, NUMBER, NUMBER, st.one_of(st.integers(-3, 300).map(str), SPECIAL))
def test_hcs_haff(phi: str, e: str, theta0: str, d: str, n: str) -> None:
    _check(_haff_args(phi, e, theta0, d, n))


def _coefficient_args(model, phi, e, theta, d, rho) -> list[str]:
    return ["coefficients", "--model", model, "--phi", phi, "--e", e, "--theta", theta, "--d", d, "--rho-s", rho,
            "--format", "json"]


@FAST
@given(st.sampled_from(["ret", "enskog", "visc-div", "proposed", "x"]), VALUES, VALUES, NUMBER, NUMBER, NUMBER)
def test_coefficients(model: str, phi: str, e: str, theta: str, d: str, rho: str) -> None:
    _check(_coefficient_args(model, phi, e, theta, d, rho))


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                 HealthCheck.function_scoped_fixture])
@given(NUMBER, NUMBER, st.sampled_from([".png", ".txt", "", ".svg", ".nc", ".PDF", "/"]),
       st.one_of(st.none(), NUMBER))
def test_plot_dispersion(tmp_path_factory, phi: str, e: str, ext: str, k_max: str | None) -> None:
    out = tmp_path_factory.mktemp("fig") / f"d{ext}"
    args = ["plot", "dispersion", "--phi", phi, "--e", e, "-o", str(out)]
    _check(args + (["--k-max", k_max] if k_max is not None else []))


@pytest.mark.slow(minutes=1.6)
@LONG
@given(MODELS, VALUES, VALUES, st.one_of(st.none(), NUMBER), NUMBER, NUMBER, NUMBER)
def test_long_fuzz(model: str, phi: str, e: str, box: str | None, theta: str, d: str, rho: str) -> None:
    _check(_stability_args(model, phi, e, box))
    _check(_haff_args(phi, e, theta, d, "50"))
    _check(_coefficient_args(model.split(",")[0], phi, e, theta, d, rho))
