"""Wheel-rail creep forces with Kalker's FastSim, extended to non-elliptical areas by MAE."""
