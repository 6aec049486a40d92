"""amontons: multi-asperity contact experiments, from raw images to Amontons-deviation plots."""

__version__ = "0.1.0"
