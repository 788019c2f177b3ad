"""``lenslab validate``: render Mitsuba 3 scenes with LensLab and with Mitsuba 3, and compare.

``metrics`` holds the pure-numpy figures (block bias, relative MSE), ``mitsuba_env`` finds a usable Mitsuba,
``runner`` renders and compares, ``report`` prints the table and writes docs/validation.md, ``cli`` is the
command. Nothing here imports Qt; Mitsuba is imported only when a scene is rendered with it.
"""
