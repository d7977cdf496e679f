"""Shared test helpers (not tests): synthetic calibration data, small 3D cases, growth-rate fits, CF units.

Importable as ``helpers.<module>`` because pytest puts the folder of the root ``conftest.py`` on ``sys.path``.
"""
