"""The project's validation studies: convergence, checks against independent solutions,
the transition's fits and normal forms.  Each module answers one question, is cited by a
page of docs/validation/ and has a ``main()`` that parses its own options.

Run one with ``python -m studies NAME [options]`` from the repository's top; ``python -m
studies`` alone prints the index (``studies/README.md`` has the full table: command, run
time, CSV, the page that cites it).  Not part of the distribution and not collected by
pytest.  The studies share ``benchmarks/_harness.py`` (timing, CSV writing) with the
benchmarks and write their tables to ``benchmarks/results/`` as before.
"""
