"""Zarr and OME-Zarr label images, read lazily (:class:`meshcurv._lazy.LazyImage`); needs the ``zarr`` package.

A path ending in ``.zarr`` (a folder) is opened with :func:`zarr.open`
(Zarr format 2 or 3):

- an array: the image, its voxel size unknown;
- an OME-Zarr image (NGFF 0.4 ``multiscales`` in the group's attributes, or
  0.5 under ``ome``): its first (full-resolution) dataset, the voxel size
  its ``scale`` transformations (the dataset's times the multiscale's) along
  the axes named ``z``, ``y``, ``x``, and their unit when they all share
  one; axes ``t`` and ``c`` must have length 1 and are dropped;
- a group of one array, or of an array named ``labels``: that array.

Nothing is read but the metadata: :mod:`meshcurv.volume` reads the image a
chunk at a time to find the objects, then each object's box.
"""

from __future__ import annotations

import pathlib

import numpy as np

from .._lazy import LazyImage
from ..errors import InvalidMeshError, MeshFileError, optional_module

__all__ = ["read_zarr", "ZARR_INSTALL"]

ZARR_INSTALL = "pip install 'meshcurv[volume]' (or: pip install zarr)"


def _zarr():
    return optional_module("zarr", f"reading Zarr images needs the zarr package: {ZARR_INSTALL}")


def _multiscales(attributes) -> list | None:
    attributes = dict(attributes)
    ome = attributes.get("ome")
    if isinstance(ome, dict) and "multiscales" in ome:
        return ome["multiscales"]
    return attributes.get("multiscales")


def _scale(transformations) -> np.ndarray | None:
    for transform in transformations or []:
        if isinstance(transform, dict) and transform.get("type") == "scale":
            return np.asarray(transform.get("scale"), dtype=float)
    return None


def _ome(path, group, multiscales):
    """``(array, axes selection, spacing, unit)`` of the first dataset of an OME-Zarr image."""
    try:
        scale = multiscales[0]
        dataset = scale["datasets"][0]
        array = group[dataset["path"]]
        axes = scale.get("axes") or [{"name": name} for name in "tczyx"[-len(array.shape) :]]
        names = [axis["name"] if isinstance(axis, dict) else str(axis) for axis in axes]
    except (KeyError, IndexError, TypeError) as exc:
        raise MeshFileError(
            f"{path}: the OME-Zarr 'multiscales' metadata is incomplete ({type(exc).__name__}: {exc})"
        ) from None
    if len(names) != len(array.shape) or not {"z", "y", "x"} <= set(names):
        raise MeshFileError(
            f"{path}: an OME-Zarr image with axes z, y, x is needed; its axes are {names} for "
            f"shape {tuple(array.shape)}"
        )
    selection: list[int | None] = []
    for name, n in zip(names, array.shape):
        if name in ("z", "y", "x"):
            selection.append(None)
        elif n == 1:
            selection.append(0)
        else:
            raise MeshFileError(
                f"{path}: the OME-Zarr axis {name!r} has length {n}; one 3D image (z, y, x) is "
                "needed: save one time point and channel"
            )
    order = [names.index(name) for name in ("z", "y", "x")]
    if order != sorted(order):
        raise MeshFileError(f"{path}: the OME-Zarr axes are {names}; meshcurv reads them in the order z, y, x")
    spacing = None
    local, whole = _scale(dataset.get("coordinateTransformations")), _scale(scale.get("coordinateTransformations"))
    if local is not None and local.shape == (len(names),):
        values = local * (whole if whole is not None and whole.shape == local.shape else 1.0)
        values = values[order]
        if np.isfinite(values).all() and (values > 0).all():
            spacing = tuple(float(v) for v in values)
    units = {axes[k].get("unit") for k in order if isinstance(axes[k], dict)}
    unit = units.pop() if len(units) == 1 and None not in units else None
    return array, tuple(selection), spacing, unit


def read_zarr(path) -> tuple[LazyImage, tuple[float, float, float] | None, str | None]:
    """``(image, spacing (z, y, x) or None, unit or None)`` of a Zarr or OME-Zarr store, nothing read but metadata.

    Raises
    ------
    MeshFileError
        Not a Zarr store; a group with no array, or several and none named
        ``labels``; an OME-Zarr image without z, y, x axes or with a time or
        channel axis longer than 1; not 3D. The message names the path.
    MissingDependencyError
        zarr is not installed (``pip install zarr``).
    """
    zarr = _zarr()
    path = pathlib.Path(path)
    if not path.exists():
        raise MeshFileError(f"{path}: no such file or folder")
    try:
        node = zarr.open(str(path), mode="r")
    except Exception as exc:
        raise MeshFileError(f"{path}: cannot be opened as Zarr ({type(exc).__name__}: {str(exc)[:200]})") from exc
    selection, spacing, unit = None, None, None
    if isinstance(node, zarr.Group):
        multiscales = _multiscales(node.attrs)
        if multiscales:
            node, selection, spacing, unit = _ome(path, node, multiscales)
        else:
            names = sorted(node.array_keys())
            if "labels" in names:
                node = node["labels"]
            elif len(names) == 1:
                node = node[names[0]]
            else:
                raise MeshFileError(
                    f"{path}: a Zarr group of several arrays (or none) needs one named 'labels', or "
                    f"OME-Zarr 'multiscales' metadata; found arrays {names}"
                )
    if selection is None:
        shape = tuple(int(n) for n in node.shape)
        if len(shape) > 3 and sum(n != 1 for n in shape) <= 3:  # axes of length 1 dropped, as the other readers
            keep = [k for k, n in enumerate(shape) if n != 1]
            keep = ([k for k in range(len(shape)) if k not in keep][: 3 - len(keep)] + keep) if len(keep) < 3 else keep
            selection = tuple(None if k in keep else 0 for k in range(len(shape)))
    try:
        image = LazyImage(node, axes=selection)
    except InvalidMeshError:
        raise MeshFileError(
            f"{path}: a 3D image (z, y, x) is needed; the store holds shape {tuple(int(n) for n in node.shape)}"
        ) from None
    return image, spacing, unit
