"""Reissner-Mindlin plate: spaces, MITC shear interpolation, UFL forms, assembled pencil."""

from unibuckle_fenicsx.model.plate.model import PlateModel

__all__ = ["PlateModel"]
