"""Stripmap scene simulator: scene TOML -> raw echo product.

Modules: ``scene`` (TOML -> dataclasses), ``effects`` (registry, one module per effect),
``context`` (what the listed effects switched on), ``platform`` (trajectory truth per pulse),
``pointing`` (antenna axes), ``geometry`` (targets on the ellipsoid / flat Earth, Doppler truth),
``clutter`` (random-phase scatterers), ``kernel`` (numba echo kernel + numpy reference),
``truth`` (targets table, Doppler truth), ``stripmap`` (``simulate(scene) -> RawProduct``).
"""
