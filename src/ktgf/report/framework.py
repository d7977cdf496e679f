"""The report's building blocks: sections, what they produce, the on-disk cache and the build loop.

A *section* is a function ``run(ctx)`` that turns inputs into figures (PNG, each with the
netCDF file of the data behind it), tables, paragraphs and named numbers, all recorded in
the :class:`SectionContext` it is given.  Its result is cached in ``<out>/.cache/<key>.json``
under a hash of everything it depends on: the section's declared inputs (settings, model
options), the ktgf version, the source code of the section's modules and the content of the
data files it reads.  A rerun therefore recomputes only sections whose inputs changed or that
were never finished (an interrupted run continues where it stopped).

Layout of the output folder::

    index.html                the page (figures referenced by relative path)
    figures/<section>/*.png   figures
    data/<section>/*.nc       the data behind every figure (ktgf.io.run_metadata attrs)
    .cache/<section>.json     cached results; .cache/log.jsonl one line per section per run
"""

from __future__ import annotations

import hashlib
import importlib
import json
import os
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from .._version import __version__
from ..errors import InputError
from .results import GENERATOR, PAGE_NAME, FigureRef, SectionResult, TableData  # noqa: F401  (the sections' types)
from .settings import ReportSettings

CACHE_DIR = ".cache"
FIGURE_DIR = "figures"
DATA_DIR = "data"
#: Bump to invalidate every cache entry when the result format changes.
CACHE_FORMAT = 1


class SectionContext:
    """What a section's ``run`` gets: its settings, the DEM data folder and places to put its outputs."""

    def __init__(self, section: Section, settings: ReportSettings, out: Path, data_dir: Path | None,
                 inputs: dict[str, Any], progress: Callable[[str, str, str], None] | None = None) -> None:
        self._progress = progress
        self.section = section
        self.settings = settings
        self.out = out
        self.data_dir = data_dir
        self.inputs = inputs
        self.result = SectionResult(section.key, section.title, inputs=inputs)

    def step(self, text: str) -> None:
        """Report progress inside a long section (shown by ``ktgf reproduce`` next to the section's title)."""
        if self._progress is not None:
            self._progress(self.section.key, text, "step")

    # -- inputs ---------------------------------------------------------------------------
    def data_file(self, name: str) -> Path | None:
        """Path of the optional DEM file ``name``, or None after adding a note saying it is absent."""
        if self.data_dir is not None and (self.data_dir / name).is_file():
            return self.data_dir / name
        where = f"in {self.data_dir}" if self.data_dir is not None else "(no DEM data folder)"
        self.note(f"Optional DEM reference file {name} not found {where}: the comparison with it is left out.")
        return None

    # -- outputs --------------------------------------------------------------------------
    def figure(self, fig: Any, name: str, caption: str, data: Any = None) -> str:
        """Save a matplotlib figure as ``figures/<section>/<name>.png`` and ``data`` (its Dataset) as netCDF."""
        from ..plotting import save

        save(fig, self.figure_path(name))
        return self.add_figure(name, caption, data)

    def figure_path(self, name: str) -> Path:
        """Where figure ``name`` goes, for plotting functions that save the file themselves."""
        return self.out / FIGURE_DIR / self.section.key / f"{name}.png"

    def add_figure(self, name: str, caption: str, data: Any = None) -> str:
        """Record figure ``name`` (already saved at :meth:`figure_path`) with its data."""
        rel = self.figure_path(name).relative_to(self.out).as_posix()
        nc = self.dataset(data, name) if data is not None else None
        self.result.figures.append(FigureRef(rel, caption, nc))
        return rel

    def dataset(self, ds: Any, name: str) -> str:
        """Write an xarray Dataset to ``data/<section>/<name>.nc``; return its relative path."""
        from ..io import write_netcdf

        rel = f"{DATA_DIR}/{self.section.key}/{name}.nc"
        write_netcdf(ds, self.out / rel)
        self.result.datasets.append(rel)
        return rel

    def table(self, title: str, columns: list[str], rows: list[list[Any]], note: str = "", *, with_figure: bool = True) -> None:
        """Add a table, shown right after the last figure added (``with_figure=False``: at the section's end)."""
        fig = self.result.figures[-1].file if with_figure and self.result.figures else None
        self.result.tables.append(TableData(title, list(columns), [list(r) for r in rows], note, fig))

    def paragraph(self, text: str) -> None:
        self.result.paragraphs.append(text)

    def note(self, text: str) -> None:
        self.result.notes.append(text)

    def number(self, key: str, value: Any) -> None:
        """A named number for the discussion (plain JSON values: float, int, str, lists, dicts)."""
        self.result.numbers[key] = _plain(value)


def _plain(x: Any) -> Any:
    """Convert NumPy scalars/arrays inside ``x`` to JSON values (NaN/inf kept as floats)."""
    import numpy as np

    if isinstance(x, dict):
        return {str(k): _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, np.ndarray):
        return _plain(x.tolist())
    if isinstance(x, np.generic):
        return x.item()
    return x


@dataclass(frozen=True)
class Section:
    """One section of the report.

    Parameters
    ----------
    key, title : str
        Identifier (folder and HTML id) and heading.
    run : callable
        ``run(ctx: SectionContext) -> None``; records its outputs in ``ctx``.
    inputs : callable
        ``inputs(settings) -> dict`` of every setting and model option the section uses (cache key).
    order : int
        Position on the page.
    data_files : tuple of str
        Optional DEM files it reads (their content enters the cache key).
    modules : tuple of str
        Modules whose source code enters the cache key besides the one defining ``run``.
    available : callable
        ``available() -> str | None``: None if the section can run, else the reason it cannot.
    discuss : callable
        ``discuss(numbers) -> list of str``: sentences for the discussion, from the section's
        numbers (run at page time, so cached results are discussed too).
    """

    key: str
    title: str
    run: Callable[[SectionContext], None]
    inputs: Callable[[ReportSettings], dict[str, Any]]
    order: int
    data_files: tuple[str, ...] = ()
    modules: tuple[str, ...] = ()
    available: Callable[[], str | None] = lambda: None
    discuss: Callable[[dict[str, Any]], list[str]] = lambda numbers: []


_SECTIONS: dict[str, Section] = {}


def register_section(section: Section) -> Section:
    """Add (or replace) a section of the report."""
    _SECTIONS[section.key] = section
    return section


def sections() -> list[Section]:
    """Registered sections in page order."""
    return sorted(_SECTIONS.values(), key=lambda s: s.order)


def model_inputs(names: tuple[str, ...] | list[str]) -> dict[str, Any]:
    """Model names with their full metadata (parts, options, references), for a section's inputs."""
    from ..closures.models import get_model

    return {n: get_model(n).metadata() for n in names}


# -- cache ------------------------------------------------------------------------------
#: Packages/modules every section depends on (their source enters every cache key).
CORE_CODE = ("ktgf.closures", "ktgf.hcs", "ktgf.io", "ktgf.plotting", "ktgf.report.framework")


def _package_hash(name: str) -> str:
    """Hash of a module's source, or of every .py file of a package."""
    try:
        mod = importlib.import_module(name)
    except ModuleNotFoundError:
        return "absent"
    if getattr(mod, "__file__", None) is None:  # no source available (frozen install): the version decides
        return __version__
    base = Path(mod.__file__).parent
    files = sorted(base.rglob("*.py")) if hasattr(mod, "__path__") else [Path(mod.__file__)]
    h = hashlib.sha256()
    for f in files:
        h.update(f.relative_to(base).as_posix().encode())
        h.update(f.read_bytes())
    return h.hexdigest()[:16]


def _file_hash(path: Path | None) -> str:
    if path is None or not path.is_file():
        return "absent"
    return hashlib.sha256(path.read_bytes()).hexdigest()[:16]


def cache_record(section: Section, settings: ReportSettings, data_dir: Path | None) -> dict[str, Any]:
    """Everything a section's result depends on (hashed into its cache key)."""
    mods = (section.run.__module__, *section.modules)
    return {
        "format": CACHE_FORMAT,
        "section": section.key,
        "ktgf_version": __version__,
        "inputs": _plain(json.loads(json.dumps(section.inputs(settings), default=str))),
        "code": {**{m: _package_hash(m) for m in CORE_CODE}, **{m: _package_hash(m) for m in mods}},
        "data": {f: _file_hash(data_dir / f if data_dir else None) for f in section.data_files},
    }


def record_hash(record: dict[str, Any]) -> str:
    return hashlib.sha256(json.dumps(record, sort_keys=True, default=str).encode()).hexdigest()


def _atomic_write(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name, suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def file_digest(path: Path) -> dict[str, Any]:
    """Size and SHA-256 of a file (what the cache records of every file a section wrote)."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return {"size": path.stat().st_size, "sha256": h.hexdigest()}


def damaged_files(out: Path, manifest: dict[str, Any]) -> list[str]:
    """Files of a cache entry's manifest that are missing or differ (size or hash) from what was written."""
    bad = []
    for rel, want in manifest.items():
        f = out / rel
        try:
            if f.stat().st_size != want.get("size") or file_digest(f)["sha256"] != want.get("sha256"):
                bad.append(f"{rel} (size or SHA-256 differs from what its section wrote)")
        except OSError:
            bad.append(f"{rel} (missing)")
    return bad


def load_cached(out: Path, key: str, digest: str) -> SectionResult | None:
    """The cached result of section ``key`` if its hash matches and every file it wrote is still
    there with the size and SHA-256 recorded when it was written (a truncated figure or an
    emptied netCDF file makes the section run again)."""
    path = out / CACHE_DIR / f"{key}.json"
    try:
        entry = json.loads(path.read_text(encoding="utf-8"))
        if entry.get("hash") != digest:
            return None
        result = SectionResult.from_json(entry["result"])
        manifest = entry["files"]
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return None
    if not isinstance(manifest, dict) or set(manifest) != set(result.files()) or damaged_files(out, manifest):
        return None
    result.status = "cached"
    return result


def store_cached(out: Path, result: SectionResult, digest: str, record: dict[str, Any]) -> None:
    files = {f: file_digest(out / f) for f in result.files() if (out / f).is_file()}
    entry = {"hash": digest, "record": record, "result": result.to_json(), "files": files}
    _atomic_write(out / CACHE_DIR / f"{result.key}.json", json.dumps(entry, indent=1, default=str))


def log_event(out: Path, key: str, status: str, digest: str = "") -> None:
    """Append one line to ``.cache/log.jsonl`` (how tests and users see what was recomputed)."""
    with open(out / CACHE_DIR / "log.jsonl", "a", encoding="utf-8") as fh:
        fh.write(json.dumps({"section": key, "status": status, "hash": digest[:16]}) + "\n")


def clear_section_outputs(out: Path, key: str) -> None:
    for sub in (FIGURE_DIR, DATA_DIR):
        shutil.rmtree(out / sub / key, ignore_errors=True)


def prepare_out_dir(out: Path) -> Path:
    """Create the output folder and check it is writable; InputError (one line) otherwise."""
    out = Path(out)
    page = out / PAGE_NAME
    try:
        if page.is_file() and f'content="{GENERATOR}"' not in page.read_text(encoding="utf-8", errors="replace")[:2000]:
            raise InputError(f"{str(out)!r} already holds an index.html that ktgf did not write; choose another folder with --out")
    except OSError:
        pass  # unreadable: the write test below reports it
    try:
        out.mkdir(parents=True, exist_ok=True)
        (out / CACHE_DIR).mkdir(exist_ok=True)
        probe = out / CACHE_DIR / ".write-test"
        probe.write_text("ok")
        probe.unlink()
    except OSError as exc:
        reason = exc.strerror or str(exc)
        raise InputError(f"cannot write the report to {str(out)!r}: {reason} (choose another folder with --out)") from None
    return out


def closest(values: dict[str, float], tol: float = 1e-4) -> list[str]:
    """Names whose value (an error magnitude) is within ``tol`` of the smallest: ties are reported as ties."""
    best = min(values.values())
    return [n for n, v in values.items() if v <= best + tol]


def join_labels(names: list[str]) -> str:
    """'Enskog', 'Enskog and RET', 'Enskog, RET and Proposed' from registry names."""
    from ..closures.models import get_model

    labels = [get_model(n).label or n for n in names]
    return labels[0] if len(labels) == 1 else ", ".join(labels[:-1]) + " and " + labels[-1]
