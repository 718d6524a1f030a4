"""Data files shipped with pamsim, each with a header saying where its numbers come from.

- ``acra2012_steady_state.csv``: the ACRA 2012 paper's steady states of its step-pressure,
  hanging-weight tests (read by :func:`pamsim.paperdata.acra2012_steady_state`);
- ``mpam_survey_45mm_points.csv``: the measured point of the survey's 45 mm miniature muscle;
- ``static_model_reference_points.csv``: the numbers the static-model papers print
  (read by :func:`pamsim.static_models.reference.reference_points`).
"""
