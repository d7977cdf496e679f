"""Bad input: a clear error naming the argument, its value and the valid range — never a silent NaN."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from ktgf import InputError, UnknownModelError, get_model
from ktgf.cli import app

runner = CliRunner()


@pytest.mark.contract
@pytest.mark.parametrize(
    "model, phi, e, fragment",
    [
        ("ret", -0.1, 0.9, "solid fraction phi = -0.1"),
        ("ret", 1.0, 0.9, "phi < 1"),
        ("proposed", 0.64, 0.9, "phi < 0.64"),
        ("visc-div", 0.7, 0.9, "packing limit"),
        ("ret", 0.3, 0.0, "restitution coefficient e = 0"),
        ("ret", 0.3, 1.2, "0 < e <= 1"),
        ("enskog", np.nan, 0.9, "nan"),
        ("visc-div", [0.1, 0.2, 0.9, 0.95], 0.9, "= 0.9 (and 1 more)"),
    ],
)
def test_out_of_range_state_raises(model, phi, e, fragment):
    m = get_model(model)
    with pytest.raises(InputError) as info:
        m.reduced(phi, e)
    assert fragment in str(info.value)
    assert isinstance(info.value, ValueError)


@pytest.mark.contract
def test_temperature_and_sizes_are_checked():
    m = get_model("ret")
    with pytest.raises(InputError, match="granular temperature theta = -1"):
        m.coefficients(0.3, 0.9, -1.0, d=1e-3, rho_s=1500.0)
    with pytest.raises(InputError, match="particle diameter d = 0"):
        m.coefficients(0.3, 0.9, 1.0, d=0.0, rho_s=1500.0)


@pytest.mark.contract
def test_unknown_model_and_option():
    with pytest.raises(UnknownModelError, match="registered models: enskog, ret"):
        get_model("navier")
    with pytest.raises(InputError, match="no option"):
        get_model("ret", colour="red")
    with pytest.raises(InputError, match="zeta11"):
        get_model("ret", zeta11="new")


@pytest.mark.contract
@pytest.mark.parametrize(
    "args, fragment",
    [
        (["--model", "ret", "--phi", "0.7", "--e", "0.9", "--format", "json"], None),
        (["--model", "proposed", "--phi", "0.7", "--e", "0.9"], "phi < 0.64"),
        (["--model", "ret", "--phi", "0.3", "--e", "1.5"], "0 < e <= 1"),
        (["--model", "nope", "--phi", "0.3", "--e", "0.9"], "unknown model"),
        (["--model", "ret", "--phi", "a:b", "--e", "0.9"], "range start:stop:num"),
    ],
)
def test_cli_coefficients_errors_exit_2_with_one_line(args, fragment):
    result = runner.invoke(app, ["coefficients", *args])
    if fragment is None:
        assert result.exit_code == 0, result.output
        return
    assert result.exit_code == 2
    lines = [ln for ln in result.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("Error:") and fragment in lines[0]


@pytest.mark.published
def test_cli_coefficients_values_match_library():
    result = runner.invoke(app, ["coefficients", "-m", "ret", "--phi", "0.1:0.5:3", "--e", "0.9,0.7", "--format", "json"])
    assert result.exit_code == 0, result.output
    rows = json.loads(result.output)
    assert len(rows) == 6
    row = next(r for r in rows if r["phi"] == 0.5 and r["e"] == 0.9)
    assert row["eta*"] == pytest.approx(18.661180, rel=1e-6)  # oracles.md RET table
    assert row["p [Pa]"] == pytest.approx(1500.0 * 0.5 * 1e-2 * 12.4, rel=1e-12)


@pytest.mark.contract
def test_cli_models_lists_registry():
    result = runner.invoke(app, ["models", "--format", "csv"])
    assert result.exit_code == 0
    assert {"enskog", "ret", "visc-div", "proposed"} <= {ln.split(",")[0] for ln in result.output.splitlines()}


@pytest.mark.contract
def test_cli_plot_coefficients(tmp_path):
    out = tmp_path / "fig" / "coefficients.png"
    result = runner.invoke(app, ["plot", "coefficients", "--e", "0.8", "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert out.stat().st_size > 20_000


@pytest.mark.contract
def test_arrays_that_do_not_broadcast_are_one_line_input_errors() -> None:
    """Found by the property test of tests/hcs: φ of shape (2,) with e of shape (3,) was a NumPy ValueError."""
    from ktgf import get_model

    for name in ("enskog", "ret", "dense"):
        with pytest.raises(InputError, match=r"^arrays of shapes phi \(2,\), e \(3,\) do not broadcast together"):
            get_model(name).reduced([0.1, 0.2], [0.9, 0.9, 0.9])
