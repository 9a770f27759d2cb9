"""Eigen-gaits (Li et al. 2009): functional PCA of example cycles, and synthesis from coefficients,
step-length labels, or a required pose. Pure numpy/scipy; I/O only for the model ``.npz``."""

from .example_cycles import ExampleCycle, ExampleError, cycles_from_trajectory, detect_heel_strikes, walk_label
from .legs import PlanarLegs, SpatialLegs
from .model import EigenGaitModel, EigenModelError, FitOptions, fit_model, is_model_file
from .synth import WalkEnds, root_from_contact, synthesize_cycles, synthesize_walk

__all__ = ["ExampleCycle", "ExampleError", "cycles_from_trajectory", "detect_heel_strikes", "walk_label",
           "EigenGaitModel", "EigenModelError", "FitOptions", "fit_model", "is_model_file", "PlanarLegs",
           "root_from_contact", "SpatialLegs", "synthesize_cycles", "synthesize_walk", "WalkEnds"]
