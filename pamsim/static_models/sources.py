"""Citations of the papers the static models come from (authors, title, venue, year)."""

ACRA2012 = ("'A dynamic force model of a small and soft McKibben pneumatic muscle', Australasian Conference "
            "on Robotics and Automation (ACRA), 2012")
KOTHERA2009 = ("Kothera, C. S., Jangid, M., Sirohi, J., Wereley, N. M., 'Experimental characterization and "
               "static modeling of McKibben actuators', Journal of Mechanical Design 131, 2009")
SURVEY = ("'A survey on static modeling of miniaturized pneumatic artificial muscles with new model and "
          "experimental results' (the survey; authors and venue are not in the source text)")
OGDEN = ("'An enhanced static model of braided pneumatic muscle actuators with an Ogden bladder' "
         "(Festo DMSP-20-120-RM-CM), Hindawi, 2014, doi:10.1155/2014/425217 (title paraphrased from the abstract)")
