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
    from ..io import atomic_path

    out = Path(out)
    formats = fig.canvas.get_supported_filetypes()
    if out.suffix.lower().lstrip(".") not in formats:
        plt.close(fig)
        raise InputError(f"figure file {str(out)!r} has extension {out.suffix or '(none)'!r}: "
                         f"valid {', '.join('.' + f for f in sorted(formats))}")
    try:
        with atomic_path(out) as tmp:  # a figure is complete or absent, never half-written
            fig.savefig(tmp, dpi=150, bbox_inches="tight")
    except (PermissionError, OSError) as exc:
        raise InputError(f"cannot write figure {str(out)!r}: {exc.strerror or exc}") from exc
    finally:
        plt.close(fig)
    return out
