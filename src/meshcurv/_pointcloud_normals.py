"""Neighbours, spacing, normals and their orientation for point clouds (:mod:`meshcurv.pointcloud`).

Normals are estimated by principal component analysis of the k nearest
neighbours (the eigenvector of the smallest eigenvalue of their covariance)
and oriented consistently by propagation along a minimum spanning tree of the
k-nearest-neighbour graph weighted by ``1 - |n_i . n_j|`` (Hoppe et al. 1992):
the tree follows the pairs of most parallel normals, where the relative sign
is least ambiguous. The sign of every point relative to its tree's root is the
product of the signs ``sign(n_i . n_parent(i))`` along its path to the root,
computed by pointer jumping (``log2(depth)`` vectorised passes over the
points, no loop over them); with the compiled backend, Kruskal's algorithm
over the edges in order of weight with a union-find that keeps each point's
flip relative to its root gives the same signs in one pass
(:func:`meshcurv._kernels.pointcloud.spanning_signs`). Each connected component of the graph is then
turned outward: by the divergence theorem ``sum_i a_i n_i . (p_i - c) = 3 V > 0``
for the outward normals of a closed surface (``a_i`` the area of a point, the
square of its local spacing; ``c`` any point); on an open surface the sum
picks one side.

References
----------
H. Hoppe, T. DeRose, T. Duchamp, J. McDonald, W. Stuetzle (1992). Surface
reconstruction from unorganized points. SIGGRAPH '92, 71-78.
https://doi.org/10.1145/133994.134011
"""

from __future__ import annotations

import numpy as np

from ._backend import numba_kernels

#: Neighbours (the point itself not counted) of the k-nearest-neighbour query that
#: gives the spacing, the PCA normals and the orientation graph.
NEIGHBOURS = 10

#: The local spacing is measured at this neighbour (see :func:`local_spacing`).
SPACING_NEIGHBOUR = 8

#: Neighbours per point in the graph of the orientation (the nearest of the query's).
GRAPH_NEIGHBOURS = 6

#: With given normals, an edge of the orientation graph is steep when an end lies beyond this slope
#: (15 degrees) of the other's tangent plane (see :func:`orientation_signs`).
TANGENT_SLOPE = 0.25

#: A point keeps its steep edges (except back-to-back ones) when fewer than this many of its edges are flat.
MIN_FLAT_EDGES = 3

#: Points per chunk of the neighbour query and the PCA (bounds memory: about 100 MB).
CHUNK = 131072


def knn(tree, points: np.ndarray, k: int = NEIGHBOURS) -> tuple[np.ndarray, np.ndarray]:
    """(N, k) distances and indices of the ``k`` nearest other points of each point (chunked, all cores).

    The point itself is dropped from its row (when duplicates make it not the
    first, the first column is dropped instead: a duplicate at distance 0 is
    then also a neighbour at distance 0, which is what counts).
    """
    n = points.shape[0]
    k = min(k, n - 1)
    distances = np.zeros((n, k))
    indices = np.zeros((n, k), dtype=np.int64)
    for start in range(0, n, CHUNK):
        rows = np.arange(start, min(n, start + CHUNK))
        d, i = tree.query(points[rows], k=k + 1, workers=-1)
        _drop_self(rows, d, i, k, distances, indices)
    return distances, indices


def _drop_self(rows, d, i, k, distances, indices) -> None:
    """Write the (M, k + 1) neighbours ``d, i`` of the points ``rows``, less each point itself, into the outputs."""
    if (i[:, 0] == rows).all():  # distinct points: each is its own nearest
        distances[rows], indices[rows] = d[:, 1:], i[:, 1:]
        return
    own = i == rows[:, None]
    first = np.where(own.any(axis=1), own.argmax(axis=1), 0)
    keep = np.ones(d.shape, dtype=bool)
    keep[np.arange(rows.size), first] = False
    distances[rows] = d[keep].reshape(-1, k)
    indices[rows] = i[keep].reshape(-1, k)


def local_spacing(distances: np.ndarray) -> np.ndarray:
    """(N,) the side of the square of surface each point stands for: ``d_k sqrt(pi / k)``.

    ``d_k`` is the distance to the :data:`SPACING_NEIGHBOUR`-th neighbour: ``k``
    points in a disc of radius ``d_k`` give ``pi d_k^2 / k`` of area per point.
    On a square grid of step ``h`` it is about ``h``; it plays the part of the
    mean edge length of a mesh.
    """
    k = min(SPACING_NEIGHBOUR, distances.shape[1])
    return distances[:, k - 1] * np.sqrt(np.pi / k)


def pca_normals(points: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """(N, 3) unit normals (unoriented): the least-variance direction of each point and its neighbours.

    The compiled kernel (:func:`meshcurv._kernels.pointcloud.pca_normals`, a
    closed form) when the numba backend is in use, else :func:`numpy.linalg.eigh`
    on chunks of covariances.
    """
    kernels = numba_kernels("pointcloud")
    if kernels is not None:
        return kernels.pca_normals(points, np.ascontiguousarray(indices))
    return _pca_normals_numpy(points, indices)


def _pca_normals_numpy(points: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """The NumPy path of :func:`pca_normals`."""
    n = points.shape[0]
    normals = np.zeros((n, 3))
    for start in range(0, n, CHUNK):
        stop = min(n, start + CHUNK)
        group = np.concatenate([points[start:stop, None, :], points[indices[start:stop]]], axis=1)
        group = group - group.mean(axis=1, keepdims=True)
        covariance = np.einsum("nki,nkj->nij", group, group)
        _, vectors = np.linalg.eigh(covariance)
        normals[start:stop] = vectors[:, :, 0]
    return normals


def orientation_signs(normals: np.ndarray, indices: np.ndarray, usable: np.ndarray, *, given: bool = False,
                      points: np.ndarray | None = None):
    """Signs (+1/-1) that orient ``normals`` consistently, and the component label of each point.

    Parameters
    ----------
    normals : ndarray of shape (N, 3)
        Unit normals, any signs.
    indices : ndarray of shape (N, k)
        The nearest neighbours of each point (:func:`knn`); the first
        :data:`GRAPH_NEIGHBOURS` are the graph's edges.
    usable : ndarray of shape (N,), bool
        Points that enter the graph (outliers do not; each is its own component).
    given : bool, default: False
        The signs carry information (normals given by the user): the edges
        are weighted ``1 - n_i . n_j`` instead of ``1 - |n_i . n_j|``, so that
        the tree follows agreeing pairs and crosses to an opposite normal only
        where no agreeing path exists. Consistent normals on the two sides of
        a part thinner than the spacing (whose nearest neighbours face the
        other way) then stay as they are; with ``1 - |n_i . n_j|`` the tree
        would take those anti-parallel pairs as well and flip one side.
    points : ndarray of shape (N, 3), optional
        The positions (given normals): an edge is steep where an end lies
        beyond :data:`TANGENT_SLOPE` of the other's tangent plane
        (``|n . d| > 0.25 |d|``). A steep edge is dropped where its point has
        :data:`MIN_FLAT_EDGES` flat ones, and always when its normals are
        opposite and both point away from the other point (back to back: the
        two sides of a part thinner than the neighbourhood, whose consistent
        normals must not be "corrected" into one direction). A point that
        noise lifted off its neighbours' planes keeps its other steep edges.

    Returns
    -------
    signs : ndarray of shape (N,)
        ``signs[i] * normals[i]`` is consistent with the root of its component,
        whose sign is +1.
    labels : ndarray of shape (N,), int
        Connected component of the k-nearest-neighbour graph.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import breadth_first_order, connected_components, minimum_spanning_tree

    indices = indices[:, :GRAPH_NEIGHBOURS]
    n, k = indices.shape
    rows = np.repeat(np.arange(n), k)
    cols = indices.ravel()
    keep = usable[rows] & usable[cols] & (rows != cols)
    rows, cols = rows[keep], cols[keep]
    if points is not None:
        offsets = points[cols] - points[rows]
        reach = TANGENT_SLOPE * np.linalg.norm(offsets, axis=1)
        along = np.maximum(np.abs(np.einsum("ij,ij->i", offsets, normals[rows])),
                           np.abs(np.einsum("ij,ij->i", offsets, normals[cols])))
        flat = along <= reach
        # a steep edge is dropped only where its point keeps enough flat ones: a point that noise
        # lifted off its neighbours' planes stays joined to them
        enough = np.bincount(rows, weights=flat, minlength=n) >= MIN_FLAT_EDGES
        # opposite normals that both point away from the other point: the two sides of a thin part
        ahead = np.einsum("ij,ij->i", offsets, normals[rows])
        behind = np.einsum("ij,ij->i", offsets, normals[cols])
        back_to_back = (ahead < 0) & (behind > 0) & (np.einsum("ij,ij->i", normals[rows], normals[cols]) < 0)
        keep = flat | (~enough[rows] & ~back_to_back)
        rows, cols = rows[keep], cols[keep]
    compiled = numba_kernels("pointcloud")
    if compiled is not None and points is None:  # every kept edge's cosine without (E, 3) gathers
        cosine = compiled.edge_cosines(normals, np.ascontiguousarray(indices)).ravel()[keep]
    else:
        cosine = np.einsum("ij,ij->i", normals[rows], normals[cols])
    # weight 1 - |cos| (1 - cos for given signs), plus a floor so that parallel pairs stay edges of the sparse graph
    weights = (1.0 - cosine if given else 1.0 - np.abs(cosine)) + 1e-6
    if compiled is not None:
        signs, roots = compiled.spanning_signs(
            n, rows, cols, (cosine < 0).astype(np.int8), np.argsort(weights))
        return signs, np.unique(roots, return_inverse=True)[1].reshape(-1)
    graph = coo_matrix((weights, (rows, cols)), shape=(n + 1, n + 1)).tocsr()
    # both searches treat the graph as undirected: (i, j) is an edge when either is among the other's neighbours
    n_components, labels = connected_components(graph[:n, :n], directed=False)
    # one virtual node n joined to the first point of each component: one tree for every component
    roots = np.zeros(n_components, dtype=np.int64)
    roots[labels[::-1]] = np.arange(n)[::-1]
    hub = coo_matrix((np.full(n_components, 1e-9), (np.full(n_components, n), roots)), shape=(n + 1, n + 1))
    tree = minimum_spanning_tree(graph + hub + hub.T)
    _, parent = breadth_first_order(tree, n, directed=False, return_predecessors=True)
    parent = parent[:n].astype(np.int64)
    parent[(parent == n) | (parent < 0)] = -1  # the roots (children of the hub) and the hub
    # relative sign of each point to its parent, then products along the paths by pointer jumping
    has_parent = parent >= 0
    signs = np.ones(n)
    anchor = np.where(has_parent, parent, np.arange(n))
    signs[has_parent] = np.sign(np.einsum("ij,ij->i", normals[has_parent], normals[parent[has_parent]]))
    signs[signs == 0] = 1.0
    while True:
        moved = anchor[anchor] != anchor
        if not moved.any():
            break
        signs = signs * signs[anchor]
        anchor = anchor[anchor]
    # the last pass multiplies by the sign of each path's first step at the root (+1): nothing lost
    signs = signs * signs[anchor]
    return signs, labels


def outward_signs(points: np.ndarray, normals: np.ndarray, labels: np.ndarray, areas: np.ndarray) -> np.ndarray:
    """(N,) +1 or -1 per point: -1 on the components whose normals point inward.

    ``sum_i areas_i n_i . (p_i - c)`` over a component (``c`` its centroid) is
    three times the enclosed volume for outward normals (divergence theorem).
    """
    n_labels = int(labels.max()) + 1 if labels.size else 0
    counts = np.bincount(labels, minlength=n_labels).astype(float)
    sums = np.stack([np.bincount(labels, weights=points[:, j], minlength=n_labels) for j in range(3)], axis=1)
    centroid = sums / np.maximum(counts, 1.0)[:, None]
    flux = np.bincount(labels, weights=areas * np.einsum("ij,ij->i", normals, points - centroid[labels]),
                       minlength=n_labels)
    return np.where(flux[labels] < 0, -1.0, 1.0)
