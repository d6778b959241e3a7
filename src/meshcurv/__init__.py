"""meshcurv: curvature of triangle meshes.

Principal curvatures and directions, mean and Gaussian curvature and normals at
every vertex, in 1/length, with matGeom's ``meshCurvatures`` reproduced exactly
as ``method="matgeom"``.

>>> import meshcurv
>>> torus = meshcurv.shapes.torus()
>>> r = meshcurv.principal_curvatures(torus.vertices, torus.faces)
>>> r.k_min.shape, r.dir_max.shape
((3600,), (3600, 3))
"""

import importlib

from . import errors, geometry, shapes, topology
from .curvature import METHODS, multiscale_curvatures, principal_curvatures
from .diagnosis import MeshDiagnosis, diagnose
from .errors import (
    InvalidMeshError,
    InvalidOptionError,
    MeshcurvWarning,
    MeshFileError,
    MeshQualityWarning,
    TriangulationWarning,
)
from .io import read_mesh, read_points, write_mesh, write_points
from .pointcloud import multiscale_point_cloud_curvatures, point_cloud_curvatures
from .orient import orient_faces
from .result import CurvatureResult
from .smoothing import smooth_vertex_field
from .topology import MeshTopology, triangulate_faces

__version__ = "0.1.0"

__all__ = [
    "principal_curvatures",
    "multiscale_curvatures",
    "point_cloud_curvatures",
    "multiscale_point_cloud_curvatures",
    "label_curvatures",
    "curvature_statistics",
    "volume",
    "read_mesh",
    "read_points",
    "write_points",
    "write_mesh",
    "METHODS",
    "CurvatureResult",
    "MeshTopology",
    "MeshDiagnosis",
    "diagnose",
    "orient_faces",
    "triangulate_faces",
    "smooth_vertex_field",
    "shapes",
    "geometry",
    "integrals",
    "plotting",
    "viewer",
    "topology",
    "errors",
    "InvalidMeshError",
    "InvalidOptionError",
    "MeshFileError",
    "MeshcurvWarning",
    "MeshQualityWarning",
    "TriangulationWarning",
]

#: Names imported on first use (PEP 562): modules a curvature call does not need, kept out of
#: ``import meshcurv`` (the label images and their statistics, the plots, the viewer: some 15 ms of a
#: fresh process's start, issue 31). ``name -> (module, attribute or None for the module itself)``.
_LAZY = {
    "volume": (".volume", None),
    "label_curvatures": (".volume", "label_curvatures"),
    "curvature_statistics": (".statistics", "curvature_statistics"),
    "integrals": (".integrals", None),
    "plotting": (".plotting", None),
    "viewer": (".viewer", None),
}


def __getattr__(name: str):
    if name not in _LAZY:
        raise AttributeError(f"module 'meshcurv' has no attribute {name!r}")
    module, attribute = _LAZY[name]
    value = importlib.import_module(module, __name__)
    if attribute is not None:
        value = getattr(value, attribute)
    globals()[name] = value  # once: later lookups find it without this function
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
