"""The gallery's order: the FE examples first (neck, conductance, fit, pairs, chains, clusters), then the DEM's; an
example not listed here comes last, by file name."""

import os

ORDER = ["neck_models.py", "semisphere.py", "fit_law.py", "unequal_pair.py", "chain.py", "cluster.py",
         "fit_law_in_dem.py", "packing_conductivity.py", "transient_pair.py", "kirchhoff_current.py",
         "moving_particles.py", "pack_sinter_measure.py", "contact_laws.py"]


class ExampleOrder:
    """A sphinx-gallery sort key (``within_subsection_order``)."""

    def __init__(self, src_dir):
        self.src_dir = src_dir

    def __call__(self, filename):
        name = os.path.basename(filename)
        return (ORDER.index(name), "") if name in ORDER else (len(ORDER), name)

    def __repr__(self):
        return f"<{self.__class__.__name__}>"
