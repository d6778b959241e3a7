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

from . import errors, geometry, integrals, plotting, shapes, topology, viewer
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
from .pointcloud import point_cloud_curvatures
from . import volume
from .volume import label_curvatures
from .statistics import curvature_statistics
from .orient import orient_faces
from .result import CurvatureResult
from .smoothing import smooth_vertex_field
from .topology import MeshTopology, triangulate_faces

__version__ = "0.1.0"

__all__ = [
    "principal_curvatures",
    "multiscale_curvatures",
    "point_cloud_curvatures",
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
