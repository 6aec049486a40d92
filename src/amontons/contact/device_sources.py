"""The GPU kernel set's hot element-wise passes as CUDA C sources, one kernel per pass.

On CuPy, :class:`.array_kernels.DeviceKernels` runs the element-wise part of the four
kernels of every iteration (``gap_moments``, ``direction``, ``step_dots``, ``update``) as
these user-defined kernels (``cupy.ElementwiseKernel``) in place of the array code of
:class:`.array_kernels.ArrayKernels`, which launches one kernel per operation and allocates
a temporary for each (about fifty for ``update``); on a GPU an iteration's time was those
launches, not its memory traffic (benchmarks/README.md, "The GPU route"). The sums stay the
namespace's own reductions over the terms these kernels write: CuPy's one-input sums run
on many blocks, where a user-defined ``ReductionKernel`` of several inputs reduces a whole
grid in one block (ten times slower at 2048², measured: the same README).

Each source is plain data, compiled by the namespace (:attr:`.array_backends.ArrayModule.
compile`); tests/contact/cuda_harness.py compiles the same text as C++ on the CPU, so that
CI holds the kernels' arithmetic to the array code without a GPU. The bodies follow
:mod:`.array_kernels`' element-wise functions expression for expression (the same
association), so the two agree to the last bit where the compilers keep it (nvcc may
contract ``a·b + c`` into a fused multiply-add, as numba's fast-math may).

Conventions (CuPy's): a body sees each parameter as the element of its array (a scalar
argument broadcasts); output parameters are references, read before they are written where
they are also inputs. Arrays are float64 (Pa, m), the free set ``m`` and the flags uint8 or
int8 (0 or 1).
"""

from __future__ import annotations

from dataclasses import dataclass

# helpers of the bodies: the gap, and the violator test of .array_kernels._should_join
PREAMBLE = """
__device__ inline double masked_gap(double u, double sigma, double h, double shift,
                                    unsigned char m) {
    return (sigma * u - h - shift) * m;
}
__device__ inline bool should_join(double q, double g, double ub) {
    return ((q <= 0.0) && (g < 0.0) && (q < ub)) || ((q >= ub) && (g > 0.0) && (q > 0.0));
}
"""


@dataclass(frozen=True)
class KernelSource:
    """One element-wise kernel: parameters as ``"float64 u, uint8 m"``, its body, and the
    device helpers its body calls (:data:`PREAMBLE`)."""

    name: str
    in_params: str
    out_params: str
    body: str
    preamble: str = PREAMBLE


# gap_moments' terms: a = m·(sigma·u - h - shift), a², a·t
GAP_TERMS = KernelSource(
    "amontons_gap_terms",
    "float64 u, float64 sigma, float64 h, float64 shift, uint8 m, float64 t",
    "float64 a, float64 a2, float64 at",
    "a = masked_gap(u, sigma, h, shift, m); a2 = a * a; at = a * t;",
)

# direction: t ← m·(g + beta·t - shift), and the constrained points that should be free
DIRECTION = KernelSource(
    "amontons_direction",
    "float64 u, float64 sigma, float64 h, float64 d, float64 beta, float64 shift, uint8 m, "
    "float64 p, float64 ub",
    "float64 t, int8 violator",
    """
    const double g = sigma * u - h - d;
    violator = ((m == 0) && should_join(sigma * p, g, ub)) ? 1 : 0;
    t = (g + beta * t - shift) * m;
    """,
)

# step_dots' terms: r·t, m·r
STEP_TERMS = KernelSource(
    "amontons_step_terms",
    "float64 r, float64 t, uint8 m",
    "float64 rt, float64 rm",
    "rt = r * t; rm = r * m;",
)

# update: one CG step in one pass (.array_kernels.ArrayKernels.update, same expressions);
# p, m, t, u in place; clipped and joined flag the events, cval and added the pressure the
# projection and the join added there, gj |g| at the joined points, at_bound p where
# sigma·p >= ub (products with the flag, as the array code's masks: a NaN stays a NaN)
UPDATE = KernelSource(
    "amontons_update",
    "float64 r, float64 h, float64 sigma, float64 d, float64 tau, float64 step, "
    "float64 ub, int32 keep_mask, int32 with_u",
    "float64 p, uint8 m, float64 t, float64 u, int8 clipped, int8 joined, float64 cval, "
    "float64 added, float64 gj, float64 at_bound",
    """
    const double g = sigma * u - h - d;
    const bool free_point = m != 0;
    const double q = p - step * t;
    const double pn = sigma * q;
    const bool low = free_point && (pn < 0.0);
    const bool high = free_point && (pn > ub);
    const bool clip = low || high;
    const double pc = low ? 0.0 : (high ? ub : pn);
    const bool join = (!free_point || clip) && should_join(pc, g, ub);
    double add = -tau * g;
    double joined_p = pc + add;
    if (keep_mask) {
        const bool inside = (joined_p >= 0.0) && (joined_p <= ub);
        const double joined_in = fmin(fmax(joined_p, 0.0), ub);
        add = inside ? add : joined_in - pc;
        joined_p = joined_in;
    }
    p = join ? joined_p / sigma : (clip ? pc / sigma : q);
    if (!keep_mask) {
        m = ((free_point && !clip) || join) ? 1 : 0;
        t = clip ? 0.0 : t;
    }
    if (with_u) {
        u = u - step * r;
    }
    clipped = clip ? 1 : 0;
    joined = join ? 1 : 0;
    cval = pc - pn;
    added = add;
    gj = fabs(g) * join;
    at_bound = p * (sigma * p >= ub);
    """,
)
