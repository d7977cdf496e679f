"""The reproduction report: ``ktgf reproduce`` runs the paper's model comparisons and writes one page.

Sections (each cached on disk under a hash of its inputs, see :mod:`.framework`):

1. :mod:`.coefficients` — reduced transport coefficients and RDFs of the models, DEM checks;
2. :mod:`.hcs` — Haff's law, DEM cooling rates, dispersion relations and the stability map;
3. :mod:`.couette` — Couette profiles against DEM (needs :mod:`ktgf.couette`);
4. :mod:`.cooling_gas` — 3D cooling gas below/above the critical size (needs :mod:`ktgf.solver`);
5. :mod:`.dense` — dense regime: uniform-shear η*, p* against φ and Couette wall stresses, against DEM;
6. :mod:`.friction` — frictional particles: the ``frictional`` model's uniform shear against frictional DEM;
7. :mod:`.validation` — the fitted models against every DEM file, fitted and predicted points apart;

then a discussion generated from the numbers and everything needed to rerun (:mod:`.page`).

>>> from ktgf.report import ReportSettings, build_report
>>> report = build_report(ReportSettings.preset(quick=True, out="ktgf-report"))  # doctest: +SKIP
>>> report.problems                                                               # doctest: +SKIP
[]
"""

from . import coefficients, cooling_gas, couette, dense, friction, hcs, validation  # noqa: F401  (registers the sections)
from .build import Report, ReportInterrupted, build_report
from .check import check_report
from .framework import Section, SectionContext, SectionResult, register_section, sections
from .settings import DATA_ENV, ReportSettings, locate_data_dir

__all__ = [
    "DATA_ENV", "Report", "ReportInterrupted", "ReportSettings", "Section", "SectionContext", "SectionResult",
    "build_report", "check_report", "locate_data_dir", "register_section", "sections",
]
