"""Shared pieces of the fidelity table's measures (fidelity_table, fidelity_tunnel)."""

FLAW_ANGLE_UNIAXIAL = -30.0        # the uniaxial flaw in the band convention (rises to the left) [deg]
NOT_RUN = ("not run", "not run")


def _f(v, fmt="{:.3g}"):
    return "—" if v is None else fmt.format(v)


def _ms(t):
    return "never" if t is None else f"{t * 1e3:.2f} ms"
