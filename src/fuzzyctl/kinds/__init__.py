"""Registries: one entry per kind (shape, method, norm, target); nothing outside them compares kind names."""
