"""Closure library: radial distribution functions, theories, viscosity laws and named models."""

from .coefficients import Dimensional, Reduced, eta0, kappa0, mean_free_path, nu0, to_dimensional
from .garzo_dufty1999 import GarzoDufty1999, c_star
from .lun1984 import Lun1984
from .models import PAPER_MODELS, Model, get_model, list_models, register_model
from .rdf import (
    RDFS,
    CarnahanStarling,
    ChialvoSundaresan,
    CustomRDF,
    LunSavage,
    MaAhmadi,
    RadialDistribution,
    Torquato,
    ViscosityDivergence,
    get_rdf,
)
from .viscosity_divergence import NoViscosityCorrection, ViscosityDivergenceLaw

__all__ = [
    "Dimensional", "Reduced", "eta0", "kappa0", "mean_free_path", "nu0", "to_dimensional",
    "GarzoDufty1999", "c_star", "Lun1984",
    "PAPER_MODELS", "Model", "get_model", "list_models", "register_model",
    "RDFS", "CarnahanStarling", "ChialvoSundaresan", "CustomRDF", "LunSavage", "MaAhmadi",
    "RadialDistribution", "Torquato", "ViscosityDivergence", "get_rdf",
    "NoViscosityCorrection", "ViscosityDivergenceLaw",
]
