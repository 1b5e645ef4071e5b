"""Kirsch solution for a circular opening in an infinite, isotropic, linear elastic plate under
biaxial far-field stress (paper Sec. 3.1, Eqs. 41-42, after Howard and Fast 1970).

Convention here is the paper's: stresses are COMPRESSION POSITIVE [Pa]. The solution is linear in
(σ_H, σ_h, P), so tension-positive inputs give tension-positive outputs as long as P follows the
same convention. θ is measured counter-clockwise from the σ_H (major principal) direction.
"""
import numpy as np


def polar(r, theta, a, sigma_H, sigma_h, P=0.0):
    """Radial, hoop and shear stress (σ_r, σ_θ, τ_rθ) at distance r ≥ a [m] from the centre of an
    opening of radius a [m], angle θ [rad] from the σ_H direction. P: pressure on the opening wall."""
    r = np.asarray(r, float)
    theta = np.asarray(theta, float)
    if not a > 0:
        raise ValueError(f"opening radius a = {a} m must be > 0")
    q2 = (a / r) ** 2
    q4 = q2 * q2
    mean, dev = 0.5 * (sigma_H + sigma_h), 0.5 * (sigma_H - sigma_h)
    c2, s2 = np.cos(2 * theta), np.sin(2 * theta)
    sr = mean * (1 - q2) + dev * (1 + 3 * q4 - 4 * q2) * c2 + P * q2  # Eq. 41
    st = mean * (1 + q2) - dev * (1 + 3 * q4) * c2 - P * q2           # Eq. 42
    # shear stress (not printed in the paper; standard Kirsch term, zero on the lines θ = 0°, 90°)
    srt = -dev * (1 - 3 * q4 + 2 * q2) * s2
    return sr, st, srt


def cartesian(x, y, center, a, sxx_far, syy_far, P=0.0):
    """Cartesian (σ_xx, σ_yy, σ_xy) at points (x, y) [m] around an opening of radius a centred at
    `center`, for far-field σ_xx = sxx_far, σ_yy = syy_far (compression positive, no far-field
    shear). Points inside the opening (r < a) give NaN."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    dx, dy = x - center[0], y - center[1]
    r = np.hypot(dx, dy)
    phi = np.arctan2(dy, dx)  # polar angle from the x axis
    # σ_H is the larger of the two far-field stresses; θ is counted from its direction
    if sxx_far >= syy_far:
        sH, sh, theta = sxx_far, syy_far, phi
    else:
        sH, sh, theta = syy_far, sxx_far, phi - 0.5 * np.pi
    with np.errstate(divide="ignore", invalid="ignore"):
        sr, st, srt = polar(np.where(r >= a, r, np.nan), theta, a, sH, sh, P)
    c, s = np.cos(phi), np.sin(phi)
    sxx = sr * c * c + st * s * s - 2 * srt * s * c
    syy = sr * s * s + st * c * c + 2 * srt * s * c
    sxy = (sr - st) * s * c + srt * (c * c - s * s)
    return sxx, syy, sxy


def wall_hoop_stress(theta, sigma_H, sigma_h, P=0.0):
    """Hoop stress at the opening wall, σ_θ(r = a) = σ_H + σ_h − 2(σ_H − σ_h)cos 2θ − P
    (Eq. 42 at r = a): 3σ_h − σ_H at θ = 0°, 3σ_H − σ_h at θ = 90°."""
    return (sigma_H + sigma_h) - 2 * (sigma_H - sigma_h) * np.cos(2 * np.asarray(theta, float)) - P
