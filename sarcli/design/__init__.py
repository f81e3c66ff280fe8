"""SAR design calculator: resolutions, PRF window, Doppler samples, swath — with a verdict per constraint.

``relations`` holds the physics (one function per relation, each derived in its docstring),
``params`` reads a design TOML, ``report`` evaluates a design into a JSON-ready report.
"""
