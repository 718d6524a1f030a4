"""The papers pamsim is built from, cited by authors, title, venue and year.

Parameter provenance and model sources use the short labels (``REFERENCES[key].short``);
``docs/model.md`` lists the full references, and a test keeps the two in step.
Where the text pamsim was built from does not name the authors, the entry says so
rather than guess.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType


@dataclass(frozen=True)
class Reference:
    """One paper: ``short`` is the label used in provenance strings."""

    short: str
    authors: str
    title: str
    venue: str
    year: int
    doi: str = ""

    def full(self) -> str:
        """The citation as the docs print it."""
        doi = f", doi:{self.doi}" if self.doi else ""
        title = self.title if self.title.startswith(_UNTITLED) else f"\"{self.title}\""
        return f"{self.authors}, {title}, {self.venue}, {self.year}{doi}"


_UNNAMED = "authors not named in the text pamsim was built from"
_UNTITLED = "title not in the text pamsim was built from; its abstract: "

REFERENCES = MappingProxyType({
    "acra2012": Reference(
        "ACRA 2012", _UNNAMED,
        _UNTITLED + "'An enhanced dynamic force model of a type of small and soft McKibben-type pneumatic muscle "
        "(PM) actuator has been developed' (a Shadow Robot 6 mm x 300 mm muscle)",
        "Australasian Conference on Robotics and Automation (ACRA)", 2012),
    "kothera2009": Reference(
        "Kothera et al. 2009", "C. S. Kothera, M. Jangid, J. Sirohi and N. M. Wereley",
        "Experimental Characterization and Static Modeling of McKibben Actuators",
        "Journal of Mechanical Design 131(9)", 2009, "10.1115/1.3158982"),
    "mpam_survey": Reference(
        "MPAM survey", "K. P. Ashwin and A. Ghosal",
        "A Survey on Static Modeling of Miniaturized Pneumatic Artificial Muscles with New Model and "
        "Experimental Results", "Applied Mechanics Reviews 70(4)", 2018),
    "ogden2014": Reference(
        "Ogden PAM model 2014", _UNNAMED,
        _UNTITLED + "'An enhanced model is proposed to describe static property of commercial braided pneumatic "
        "muscle actuators' (Ogden bladder energy; a Festo DMSP-20-120-RM-CM)",
        "journal not named in the text (Hindawi DOI)", 2014, "10.1155/2014/425217"),
    "iso6358": Reference(
        "ISO 6358", "International Organization for Standardization",
        "Pneumatic fluid power - Determination of flow-rate characteristics of components using compressible fluids",
        "ISO 6358-1", 2013),
})
