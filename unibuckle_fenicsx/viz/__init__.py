"""Figures and studies: field data, plots, charts over a swept parameter, mesh studies."""
