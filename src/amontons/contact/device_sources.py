"""The GPU kernel set's hot element-wise passes as CUDA C sources, one kernel per pass
(and, below, the same passes as reducing kernels that take their sums in the same launch).

On CuPy, :class:`.array_kernels.DeviceKernels` (``backend="cupy-terms"``) runs the
element-wise part of the four kernels of every iteration (``gap_moments``, ``direction``,
``step_dots``, ``update``) as these user-defined kernels (``cupy.ElementwiseKernel``) in
place of the array code of :class:`.array_kernels.ArrayKernels`, which launches one kernel
per operation and allocates a temporary for each (about fifty for ``update``); on a GPU an
iteration's time was those launches, not its memory traffic (benchmarks/README.md, "The GPU
route"). Its sums are the namespace's own reductions over the terms these kernels write:
CuPy's one-input sums run on many blocks, where a user-defined ``ReductionKernel`` of
several inputs reduces a whole grid in one block (ten times slower at 2048², measured: the
same README). :class:`.array_kernels.ReducingKernels` (``backend="cupy"``) runs the same
bodies as the reducing kernels below, which take those sums themselves, block by block.

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

# add_point_responses: u[i] += Σ_k vals_k · green[(row - a_k) mod big0, (col - b_k) mod big1]
# for the k changed points (a_k, b_k) = divmod(idx_k, n1), in one pass over u (i: the flat
# index of u's element, as CuPy names it; green, idx and vals whole arrays, "raw"), the
# points added one after the other as the array code adds them
POINT_RESPONSES = KernelSource(
    "amontons_point_responses",
    "raw float64 green, raw int64 idx, raw float64 vals, int32 k, int64 n1, int64 big0, int64 big1",
    "float64 u",
    """
    const long long row = i / n1, col = i % n1;
    for (int j = 0; j < k; ++j) {
        const long long a = idx[j] / n1, b = idx[j] % n1;
        long long r = (row - a) % big0;
        long long c = (col - b) % big1;
        r = r < 0 ? r + big0 : r;
        c = c < 0 ? c + big1 : c;
        u = u + vals[j] * green[r * big1 + c];
    }
    """,
)

# relative_change's terms: q = s_new·p_new and |q - s_old·p|
RELATIVE_CHANGE = KernelSource(
    "amontons_relative_change",
    "float64 p_new, float64 s_new, float64 p, float64 s_old",
    "float64 q, float64 change",
    "q = s_new * p_new; change = fabs(q - s_old * p);",
)


# -- the passes with their sums: one launch each, a block's partial sums per launch ---------
#
# A reducing kernel runs a KernelSource's body over the points with a grid-stride loop and
# reduces some of its values (inputs, stored outputs, or per-point locals the body writes that
# are kept nowhere) in the same pass: each thread folds its points in index order, each block
# folds its threads' values through a shared-memory tree, and block b writes its partials
# into row b of a (blocks, K) array. The host (or one small sum on the device) folds the rows.
# So an iteration's pass and its sums are one launch and one read, where the terms kernels
# wrote the terms to memory and summed them with one launch each; the order of each sum is
# fixed by the point count alone (REDUCE_BLOCK, reduce_blocks), so a device's sums are
# deterministic, and tests/contact/cuda_harness.py folds in the same order on the CPU.

REDUCE_BLOCK = 256  # threads per block: the width of the shared-memory tree (a power of 2)
REDUCE_MAX_BLOCKS = 1024  # about an H100's resident threads (132 SMs × 2048) at 256 a block

TYPES = {
    "float64": "double",
    "uint8": "unsigned char",
    "int8": "signed char",
    "int32": "int",
    "int64": "long long",
}

# the fold of a max: NaN wins, as numpy's and CuPy's max propagate it
MAX_HELPER = """
__device__ inline double amontons_max(double a, double b) { return (a != a || a > b) ? a : b; }
"""


def reduce_blocks(n: int) -> int:
    """The blocks of a reducing kernel's launch over ``n`` points: one per REDUCE_BLOCK
    points, at most REDUCE_MAX_BLOCKS (the rows of its partials)."""
    return max(1, min(REDUCE_MAX_BLOCKS, -(-n // REDUCE_BLOCK)))


def parse_params(text: str) -> list[tuple[str, str]]:
    """``"float64 u, uint8 m"`` as ``[("float64", "u"), ("uint8", "m")]`` (the element-wise
    parameters; a reducing kernel has no ``raw`` one)."""
    return [tuple(p.split()) for p in text.split(",")]


@dataclass(frozen=True)
class ReducingKernel:
    """A :class:`KernelSource` run as one pass that also reduces: ``scalars`` are the input
    parameters passed as one value, ``broadcast`` those passed as one value or one per point
    (a bound: ``inf``, or a pressure per pixel), the others arrays of the points; ``stored`` the
    output parameters written to arrays (the others are per-point locals of the body);
    ``reduced`` the ``(parameter, "sum" | "max")`` folded over the points, in the order of the
    partials' columns (an output's value after the body)."""

    source: KernelSource
    scalars: tuple[str, ...]
    stored: tuple[str, ...]
    reduced: tuple[tuple[str, str], ...]
    broadcast: tuple[str, ...] = ()

    @property
    def name(self) -> str:
        return f"{self.source.name}_reduce"

    threads = REDUCE_BLOCK  # per block of a launch

    def blocks(self, n: int) -> int:
        """The blocks of a launch over ``n`` points (:func:`reduce_blocks`)."""
        return reduce_blocks(n)

    def cuda_source(self) -> str:
        """Its CUDA C source (:func:`cuda_source`)."""
        return cuda_source(self)

    def arguments(self) -> list[tuple[str, str, str]]:
        """The kernel's parameters after the point count, as ``(kind, type, name)``: kind
        ``scalar``, ``broadcast`` (an array of one value or one per point, with its step
        through the points: 0 or 1), ``in`` (an input array) or ``out`` (a stored output
        array); then the partials."""

        def kind(name):
            if name in self.scalars:
                return "scalar"
            return "broadcast" if name in self.broadcast else "in"

        ins = [(kind(name), t, name) for t, name in parse_params(self.source.in_params)]
        outs = [("out", t, n) for t, n in parse_params(self.source.out_params) if n in self.stored]
        return ins + outs

    def point_code(self) -> str:
        """The body at point ``i``, bound as CuPy binds an element-wise kernel's parameters,
        then the fold of each reduced value into ``acc<k>``."""
        lines = []
        for kind, t, name in self.arguments():
            if kind == "in":
                lines.append(f"const {TYPES[t]} {name} = {name}_[i];")
            elif kind == "broadcast":
                lines.append(f"const {TYPES[t]} {name} = {name}_[i * {name}_step];")
            elif kind == "out":
                lines.append(f"{TYPES[t]}& {name} = {name}_[i];")
        for t, name in parse_params(self.source.out_params):
            if name not in self.stored:
                lines.append(f"{TYPES[t]} {name};")
        lines.append("{" + self.source.body + "}")
        for k, (name, op) in enumerate(self.reduced):
            lines.append(f"acc{k} = {fold(op, f'acc{k}', f'(double)({name})')};")
        return "\n".join(lines)

    def signature(self, extra: str = "") -> str:
        """The parameters' C declarations: the point count, the arguments, the partials."""
        decls = ["const long long n", *([extra] if extra else [])]
        for kind, t, name in self.arguments():
            if kind == "scalar":
                decls.append(f"const {TYPES[t]} {name}")
            elif kind == "in":
                decls.append(f"const {TYPES[t]}* {name}_")
            elif kind == "broadcast":
                decls += [f"const {TYPES[t]}* {name}_", f"const long long {name}_step"]
            else:
                decls.append(f"{TYPES[t]}* {name}_")
        return ", ".join([*decls, "double* partials"])

    def initial(self) -> str:
        """The accumulators' declarations at their identities."""
        return " ".join(
            f"double acc{k} = {'0.0' if op == 'sum' else '-1.0 / 0.0'};"
            for k, (_, op) in enumerate(self.reduced)
        )

    def _slot(self, k: int, offset: str = "") -> str:
        return f"shared[{k} * {REDUCE_BLOCK} + tid{offset}]"

    def block_store(self) -> str:
        """Thread ``tid``'s accumulators into the block's shared array (its tree's leaves)."""
        return " ".join(f"{self._slot(k)} = acc{k};" for k in range(len(self.reduced)))

    def tree_step(self) -> str:
        """One level of the block's tree at thread ``tid`` (< ``s``): its slot folds in the
        slot ``s`` after it."""
        return " ".join(
            f"{self._slot(k)} = {fold(op, self._slot(k), self._slot(k, ' + s'))};"
            for k, (_, op) in enumerate(self.reduced)
        )

    def block_result(self, block: str) -> str:
        """The tree's roots into row ``block`` of the partials."""
        count = len(self.reduced)
        return " ".join(
            f"partials[{block} * {count} + {k}] = shared[{k} * {REDUCE_BLOCK}];"
            for k in range(count)
        )


def fold(op: str, a: str, b: str) -> str:
    """The C expression folding ``b`` into ``a``."""
    return f"{a} + {b}" if op == "sum" else f"amontons_max({a}, {b})"


def cuda_source(kernel: ReducingKernel) -> str:
    """The CUDA C source of ``kernel`` (``extern "C"``, named ``kernel.name``): launched with
    :func:`reduce_blocks` blocks of :data:`REDUCE_BLOCK` threads, it writes row b of the
    ``(blocks, K)`` partials (module comment above)."""
    return f"""{kernel.source.preamble}{MAX_HELPER}
extern "C" __global__ void {kernel.name}({kernel.signature()}) {{
    __shared__ double shared[{len(kernel.reduced) * REDUCE_BLOCK}];
    const unsigned int tid = threadIdx.x;
    {kernel.initial()}
    const long long stride = (long long)gridDim.x * blockDim.x;
    for (long long i = (long long)blockIdx.x * blockDim.x + tid; i < n; i += stride) {{
{kernel.point_code()}
    }}
    {kernel.block_store()}
    __syncthreads();
    for (unsigned int s = {REDUCE_BLOCK // 2}; s > 0; s >>= 1) {{
        if (tid < s) {{ {kernel.tree_step()} }}
        __syncthreads();
    }}
    if (tid == 0) {{ {kernel.block_result("blockIdx.x")} }}
}}
"""


REDUCING_GAP = ReducingKernel(
    GAP_TERMS, ("sigma", "shift"), (), (("a", "sum"), ("a2", "sum"), ("at", "sum"), ("t", "sum"))
)
REDUCING_DIRECTION = ReducingKernel(
    DIRECTION,
    ("sigma", "d", "beta", "shift"),
    ("t",),
    (("violator", "sum"), ("t", "sum")),
    broadcast=("ub",),
)
REDUCING_STEP = ReducingKernel(STEP_TERMS, (), (), (("rt", "sum"), ("rm", "sum")))
REDUCING_UPDATE = ReducingKernel(
    UPDATE,
    ("sigma", "d", "tau", "step", "keep_mask", "with_u"),
    ("p", "m", "t", "u", "clipped", "joined", "cval", "added"),
    (("p", "sum"), ("gj", "max"), ("at_bound", "sum"), ("clipped", "sum"), ("joined", "sum")),
    broadcast=("ub",),
)
REDUCING_RELATIVE_CHANGE = ReducingKernel(
    RELATIVE_CHANGE, ("s_new", "s_old"), (), (("change", "sum"), ("q", "sum"))
)
