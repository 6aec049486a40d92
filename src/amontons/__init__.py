"""amontons: multi-asperity contact experiments, from raw images to Amontons-deviation plots."""

from importlib.metadata import version

# pyproject.toml's project.version, the one place it is set (docs/deploy.md, "Cutting a release")
__version__ = version("amontons")
