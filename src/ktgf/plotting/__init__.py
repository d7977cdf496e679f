"""Matplotlib figures (non-interactive Agg backend), one module per topic."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")


def save(fig: Any, out: str | Path) -> Path:
    """Save a figure (format from the extension), creating folders, and close it."""
    import matplotlib.pyplot as plt

    from ..errors import InputError

    out = Path(out)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(out, dpi=150, bbox_inches="tight")
    except (PermissionError, OSError) as exc:
        raise InputError(f"cannot write figure {str(out)!r}: {exc.strerror or exc}") from exc
    finally:
        plt.close(fig)
    return out
