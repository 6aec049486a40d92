"""Beer–Lambert: molecules per area of a monolayer from its peak absorbance
(appendix Fig. B.1; docs/models.md §1.1)."""

from __future__ import annotations

AVOGADRO_PER_MOL = 6.02214076e23
# 1 L/(mol·cm) = 1e-3 m³ / (mol · 1e-2 m) = 0.1 m²/mol
M2_PER_MOL_PER_L_PER_MOL_CM = 0.1
# The dye in toluene (appendix Fig. B.1): 62 200 L/(mol·cm) = 6 220 m²/mol.
EPSILON_M2_PER_MOL = 62200.0 * M2_PER_MOL_PER_L_PER_MOL_CM


def surface_density_per_m2(peak_absorbance: float, epsilon_m2_per_mol: float, n_faces: int):
    """Molecules per m² of one coated face: A / (ε · n_faces) · N_A.

    The decadic absorbance A of ``n_faces`` identical monolayers in the beam, ε in m²/mol.
    """
    return peak_absorbance / (epsilon_m2_per_mol * n_faces) * AVOGADRO_PER_MOL
