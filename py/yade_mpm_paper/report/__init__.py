"""The validation report, doc/validation/report.md (scripts/paper/report.py is its command line):

    document           the folders read, the Markdown being written, figures, tables, notes
    sections           the reproduced cases: benchmarks, circular opening, line crack, stability, uniaxial, tunnel
    fidelity_sections  the fidelity table, the one-at-a-time variants and the time-step study
"""
