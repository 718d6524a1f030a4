"""Short labels of the papers the static models come from (full references: :mod:`pamsim.references`)."""

from ..references import REFERENCES

ACRA2012 = REFERENCES["acra2012"].short
KOTHERA2009 = REFERENCES["kothera2009"].short
SURVEY = REFERENCES["mpam_survey"].short
OGDEN = REFERENCES["ogden2014"].short
