"""What the tests share, none of it a test: independent references and problem families.

- :mod:`support.paths`: the repository's folders (``ROOT``, the MPI scripts' folder);
- :mod:`support.processes`: ``mpiexec`` runs and a paused ``unibuckle sweep``;
- :mod:`support.exhaustive`: the exhaustive minimum over every contact set, densely;
- :mod:`support.brackets`: soundness of a bracket route against that minimum;
- :mod:`support.families`: seeded random problem families;
- :mod:`support.stress`: the stress family's check against the exhaustive minimum;
- :mod:`support.metamorphic`: relations between the answers of related problems, and
  the random plates the sweep checks them on;
- :mod:`support.problem_files`: base problem files holding every key of the schema;
- :mod:`support.plates`: plate set-ups used by several test modules and MPI scripts;
- :mod:`support.fibres`: a box section as thin fibres, the stress of an effective section;
- :mod:`support.hermite_plate`, :mod:`support.kirchhoff`, :mod:`support.rm_triangles`:
  independent thin-plate and holed-plate references (no code of the package's
  discretisation).

The test modules import these (``from support.exhaustive import ...``, ``tests`` is on
pytest's ``pythonpath``); no test module imports another test module.
"""
