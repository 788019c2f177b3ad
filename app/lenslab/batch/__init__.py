"""Batches of shots, on one machine or a render farm: ``lenslab batch shots.toml``.

- :mod:`~lenslab.batch.spec` reads a batch file (TOML or JSON) into shots, expanding brackets and sweeps;
- :mod:`~lenslab.batch.parts` renders one shot, or one range of its samples, on a worker;
- :mod:`~lenslab.batch.farm` hands the parts to Dask's distributed scheduler and gathers what comes back;
- :mod:`~lenslab.batch.contact_sheet` lays the finished shots out on one page;
- :mod:`~lenslab.batch.cli` is the command.

The format and the farm are described in docs/batch.md.
"""
