"""The installed version of ktgf (the bottom of the package: every module may import it)."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("ktgf")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0+unknown"
