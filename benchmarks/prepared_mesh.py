"""The prepared mesh (issue 33): results before and after a refactor, and the checks and computations per call.

Run from the repository root::

    python benchmarks/prepared_mesh.py --dump results.pkl      # every case's outputs, to compare
    python benchmarks/prepared_mesh.py --compare a.pkl b.pkl   # bit for bit: the cases that differ
    python benchmarks/prepared_mesh.py --count                 # entries into _validation and derived arrays

``--dump`` runs every method on each mesh of :func:`cases` (an icosphere; a noisy
one with a needle, a repeated corner and a zero-area face; a torus wound inward;
two components at scales 1000 apart; a triangle soup; a voxel sphere wound
inward; the needle mesh wound inward) and ``multiscale_curvatures``, and keeps
``k_min, k_max, dir_min, dir_max, normals, valid, invalid_reason, radius``, the
diagnosis, the parameters and the warnings. ``--count`` gives, for a default
call of each method on an icosphere of 642 vertices, the entries into
:mod:`meshcurv._validation` from outside it (``sys.setprofile``) and the
computations of the length scales and needle vertices (also for the icosphere
wound inward, every face reversed by the orientation).
"""

import argparse
import dataclasses
import pickle
import sys
import warnings

import numpy as np

import meshcurv
from meshcurv import shapes

METHODS = ("icc", "normal_cycle", "matgeom", "quadric", "rusinkiewicz", "normal_cycle_ball", "meyer")
FIELDS = ("k_min", "k_max", "dir_min", "dir_max", "normals", "valid", "invalid_reason", "radius")


def cases() -> dict:
    """The meshes: ``{name: (vertices, faces)}``."""
    sphere = shapes.icosphere(4)
    rng = np.random.default_rng(7)
    noisy = sphere.vertices + 0.002 * rng.standard_normal(sphere.vertices.shape)
    noisy[5] *= 10.0  # a needle
    faces = np.array(sphere.faces)
    noisy[faces[40, 1]] = noisy[faces[40, 0]]  # a zero-area face (and its neighbour)
    faces = np.vstack([faces, [[faces[60, 0], faces[60, 0], faces[60, 1]]]])  # a repeated corner
    torus = shapes.torus(3.0, 1.0, 48, 24)
    small = shapes.icosphere(3, radius=1e-3, center=(5.0, 0.0, 0.0))
    two = (
        np.vstack([sphere.vertices, small.vertices]),
        np.vstack([sphere.faces, np.asarray(small.faces) + len(sphere.vertices)]),
    )
    octa = shapes.icosphere(2)
    soup = (octa.vertices[np.asarray(octa.faces).ravel()], np.arange(3 * len(octa.faces)).reshape(-1, 3))
    found = {
        "icosphere": (sphere.vertices, sphere.faces),
        "noisy_needle": (noisy, faces),
        "torus_inward": (torus.vertices, np.asarray(torus.faces)[:, ::-1]),
        "two_components": two,
        "soup": soup,
        "needle_inward": (noisy, faces[:, ::-1]),
    }
    try:
        voxel = shapes.voxel_sphere(6.0, (1.0, 1.0, 1.0), seed=1)
        found["voxel_sphere"] = (voxel.vertices, voxel.faces)
    except ImportError:  # scikit-image missing
        pass
    return found


def _record(result) -> dict:
    record = {name: getattr(result, name) for name in FIELDS}
    record["diagnosis"] = repr(dataclasses.asdict(result.diagnosis)) if result.diagnosis is not None else None
    record["parameters"] = repr(result.parameters)
    return record


def dump(path: str) -> None:
    out = {}
    for name, (vertices, faces) in cases().items():
        for method in METHODS:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                try:
                    result = meshcurv.principal_curvatures(vertices, faces, method=method)
                    out[name, method] = _record(result)
                except ValueError as error:  # a refused mesh is an outcome too
                    out[name, method] = {"error": repr(error)}
            out[name, method]["warnings"] = [str(w.message) for w in caught]
    sphere = shapes.icosphere(4)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        results = meshcurv.multiscale_curvatures(sphere.vertices, sphere.faces, [0.05, 0.1, 0.2])
    for radius, result in zip((0.05, 0.1, 0.2), results):
        out["multiscale", radius] = {**_record(result), "warnings": [str(w.message) for w in caught]}
    with open(path, "wb") as file:
        pickle.dump(out, file)
    print(f"{len(out)} cases written to {path}")


def _same(a, b) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        if a is None or b is None:
            return a is b
        return a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a, b, equal_nan=a.dtype.kind == "f")
    return a == b


def compare(first: str, second: str) -> None:
    with open(first, "rb") as file:
        a = pickle.load(file)
    with open(second, "rb") as file:
        b = pickle.load(file)
    differ = 0
    for key in sorted(set(a) | set(b), key=repr):
        if key not in a or key not in b:
            print(f"{key}: in one file only")
            differ += 1
            continue
        fields = [name for name in set(a[key]) | set(b[key]) if not _same(a[key].get(name), b[key].get(name))]
        if fields:
            differ += 1
            print(f"{key}: {', '.join(sorted(fields))} differ")
    print(f"{len(a)} and {len(b)} cases; {differ} differ")


def count() -> None:
    from meshcurv import _geometry, _validation, defects

    sphere = shapes.icosphere(3)
    meshcurv.principal_curvatures(sphere.vertices, sphere.faces)  # compiled, imported
    watched = {
        # the computations (private before the memo went, 3745c02 to this script's commit)
        "length scales": getattr(_geometry, "_vertex_length_scales", _geometry.vertex_length_scales).__code__,
        "needle vertices": getattr(defects, "_needle_vertices", defects.needle_vertices).__code__,
    }
    validation = _validation.__file__
    entries: dict = {}

    def profile(frame, event, arg):
        if event != "call":
            return
        code = frame.f_code
        for name, target in watched.items():
            if code is target:
                entries[name] = entries.get(name, 0) + 1
        if code.co_filename == validation and frame.f_back is not None:
            if frame.f_back.f_code.co_filename != validation:
                key = f"_validation.{code.co_name} from {frame.f_back.f_code.co_name}"
                entries[key] = entries.get(key, 0) + 1

    inward = np.asarray(sphere.faces)[:, ::-1]  # every face reversed by the orientation
    for method, faces in [(m, sphere.faces) for m in METHODS] + [("icc inward", inward)]:
        entries.clear()
        sys.setprofile(profile)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                meshcurv.principal_curvatures(sphere.vertices, faces, method=method.split()[0])
        finally:
            sys.setprofile(None)
        checks = sum(n for key, n in entries.items() if key.startswith("_validation."))
        print(f"{method}: {checks} entries into _validation")
        for key, n in sorted(entries.items()):
            print(f"    {n:3d}  {key}")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dump", metavar="PATH")
    parser.add_argument("--compare", nargs=2, metavar="PATH")
    parser.add_argument("--count", action="store_true")
    args = parser.parse_args(argv)
    if args.dump:
        dump(args.dump)
    if args.compare:
        compare(*args.compare)
    if args.count:
        count()


if __name__ == "__main__":
    main()
