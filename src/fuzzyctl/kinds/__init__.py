"""Registries: one entry per kind (shape, method, norm, code-generation target)."""
