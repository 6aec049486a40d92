"""Closed forms that the measurement and the simulation share (docs/models.md): Hertz,
Newton-ring order, the Gaussian FWHM/σ ratio, Beer–Lambert, the probe's emission law and the
statistics of a height map. Both halves import these; neither imports the other."""
