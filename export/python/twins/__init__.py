"""Cross-verification twins of fabkit's parts (issue 7).

- cq_*.py: CadQuery (OpenCASCADE) twins that rebuild each part family as an exact B-rep solid
  from the resolved parameters in manifest.json (never from fabkit's meshes);
- m3d_twin.py: the manifold3d twin that redoes each part's booleans from its primitives (the
  leaf meshes of the CSG tree that `fabkit export --csg` writes);
- compare.py: the per-part comparison (volume, symmetric Hausdorff distance, bounding box,
  genus) and its bounds;
- check_twins.py: the command line that runs both twins on exports and writes the report;
- step_export.py: STEP files of an export through the CadQuery twins (`fabkit export --format step`):
  one per part and the sensor-frame `assembly.step`.

fabkit embeds the modules STEP export runs (this file, cq_*.py, families.py, step_export.py;
see export/src/step.rs); the others are the test tools of tests/e2e/cad_twins.rs, run as scripts
(`python export/python/twins/check_twins.py ...`), and m3d_twin.py imports
tests/oracles/replay_csg.py.
"""
