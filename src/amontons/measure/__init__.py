"""Measurements from optical images: contact area, and later PSF, Newton rings, absorbance."""
