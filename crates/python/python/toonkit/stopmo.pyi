"""Replacement libraries for 3D-printed stop-motion (type stubs)."""
