"""Bundled configuration files of graspgait_env, shipped as ``graspgait_env.configs``.

This folder is the source of the YAML files the package reads (``objects/``, ``hands/``,
``sim/``); the build maps it to the package ``graspgait_env.configs`` so that a wheel
carries them, and :mod:`graspgait_env.resources` finds them with
:mod:`importlib.resources`. It holds no code.
"""
