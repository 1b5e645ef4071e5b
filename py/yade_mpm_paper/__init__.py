"""yade_mpm_paper: the reproduction of the spalling paper, kept beside the user package.

It imports ``yade_mpm`` and is never imported by it: a YADE user's script needs only ``yade_mpm``; the
reference scripts under scripts/paper/ import both.

    cases        scene builders of the reference cases (circular opening, line crack, uniaxial flaw, tunnel)
    validation   analytic references (Kirsch, Sneddon) and the suites that compare the solver with them
    fidelity     the measures of the paper's figures and the fidelity table built from a run's summaries
    report       the validation report's document and sections (scripts/paper/report.py puts them in order)
    batch        the glue that runs a reference script as a yade-batch job or a Dask sweep line
"""
