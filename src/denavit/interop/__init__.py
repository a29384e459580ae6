"""Talking to the rest of robotics: URDF in (DH extraction), URDF and MJCF out.

XML from strangers is parsed safely (:mod:`denavit.interop._xml`: no DTD, no entities, bounded size and depth).
Importing this package loads no XML library beyond the standard library's expat.
"""

from ._urdf_axes import FAR_FOOT, INTERSECT_TOL, PARALLEL_TOL, ROW_CASES
from ._urdf_in import (CHECK_SAMPLES, CHECK_TOL, INERTIA_CHOICES, URDF_GRAVITY, UrdfImport, from_urdf, import_urdf,
                       nearest_physical_inertia, urdf_chain_fk)
from ._mjcf_out import MJCF_BALANCE_MARGIN, MJCF_MIN_INERTIA, MJCF_MIN_MASS, to_mjcf
from ._urdf_out import to_urdf
from ._urdf_read import MAX_NUMBER_CHARS, MAX_URDF_LINKS, chain_path, default_tip, read_urdf
from ._xacro import XACRO_CPU_SECONDS, XACRO_MEMORY_BYTES, XACRO_WALL_SECONDS
from ._xml import MAX_XML_BYTES, MAX_XML_DEPTH, MAX_XML_ELEMENTS

__all__ = [
    "from_urdf",
    "to_urdf",
    "to_mjcf",
    "MJCF_MIN_MASS",
    "MJCF_MIN_INERTIA",
    "MJCF_BALANCE_MARGIN",
    "import_urdf",
    "UrdfImport",
    "read_urdf",
    "chain_path",
    "default_tip",
    "urdf_chain_fk",
    "PARALLEL_TOL",
    "INTERSECT_TOL",
    "CHECK_SAMPLES",
    "CHECK_TOL",
    "INERTIA_CHOICES",
    "URDF_GRAVITY",
    "nearest_physical_inertia",
    "FAR_FOOT",
    "ROW_CASES",
    "MAX_XML_BYTES",
    "MAX_XML_DEPTH",
    "MAX_XML_ELEMENTS",
    "MAX_URDF_LINKS",
    "XACRO_CPU_SECONDS",
    "XACRO_MEMORY_BYTES",
    "XACRO_WALL_SECONDS",
    "MAX_NUMBER_CHARS",
]
