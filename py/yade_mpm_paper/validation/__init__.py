"""References the code is checked against, kept out of the user API (``import yade_mpm`` does not load
them): analytic solutions and the suites that compare the solver with them.

    kirsch           Kirsch's plane-strain stresses around a circular opening (paper Sec. 3.1)
    sneddon          Sneddon's pressurised line crack: opening, stress ahead, K_I (paper Sec. 3.2)
    stability        the stability suite: the per-step checks and the checked run (doc/validation/stability.md)
    stability_cases  its small extreme scenes (CASES)
    line_crack       the line crack measured: opening and stress ahead vs Sneddon, crack extension vs Fig. 9
    bonded           YADE's bonded-particle model (JCFpm) on the same cases (doc/validation/mpm_vs_bonded.md)

    from yade_mpm_paper.validation import kirsch, stability
"""
