"""Analytical solution of a pressurised line crack in an infinite plane-strain elastic medium
(Sneddon 1946; paper Sec. 3.2, Eqs. 43–44). x is measured from the crack centre along the crack line,
c is the geometric half-length, a the pressurised half-length (a = c: the whole crack is loaded),
P the pressure [Pa] (positive opens the crack)."""
import numpy as np


def opening_displacement(x, P, E, nu, c, a=None):
    """Eq. 43: vertical displacement u_y(x, 0⁺) of the upper crack face [m] for |x| < c (0 outside).
    With a = c (default) this is the classical ellipse u_y = 2P(1 − ν²)/E · √(c² − x²)."""
    a = c if a is None else a
    if not (0 < a <= c):
        raise ValueError(f"pressurised half-length a = {a} m must lie in (0, c = {c}] m")
    x = np.asarray(x, float)
    inside = np.clip(c * c - x * x, 0.0, None)
    return (1 - nu ** 2) * 2 * P / E * np.sqrt(inside) * (1 - np.sqrt(1 - (a / c) ** 2))


def stress_ahead(x, P, c):
    """Eq. 44: σxx = σyy on the crack line beyond the tip (|x| > c) [Pa], tension positive:
    σ = P (|x| / √(x² − c²) − 1); σxy = 0. NaN inside the crack."""
    x = np.abs(np.asarray(x, float))
    out = np.full(x.shape, np.nan)
    m = x > c
    out[m] = P * (x[m] / np.sqrt(x[m] ** 2 - c * c) - 1)
    return out


def stress_intensity(P, c):
    """Mode-I stress intensity factor of the fully pressurised crack, K_I = P √(π c) [Pa √m]."""
    return P * np.sqrt(np.pi * c)
