// CPU fast path of ktgf.solver.fluxes.flux_divergence on a 3D grid (numerics only): periodic, or with the
// ghost cells filled by the caller.
//
// Same formulas, in the same operation order, as the JAX functions of fluxes.py, except that the face
// divergence multiplies by 1/dx where JAX divides (one rounding apart); the JAX path is the reference
// (tests/solver/test_solver_flux_kernel.py).  Each face is computed once, from cells in cache, where XLA
// recomputes the face states in each of the five flux components (docs/solver.md, Speed).
//
// Entry points (they share the face sweep):
// * KtgfFluxDivergence: float64 (dx, dy, dz, rho_s), then the cell fields (enum Field, each (n0, n1, n2),
//   C order) -> -div F of the five conservative fields and the central div u.
// * KtgfSsprkStage: one SSP-RK3 stage U' = a U0 + (1 - a)(Uk + dt L), L = -div F + s0 + s1 div u (the
//   cooling rate is linear in div u, model.md §1) + the body force rho g and its power; inputs float64 (dx, dy,
//   dz, rho_s, a, dt, g_x, g_y, g_z), then the cell fields at Uk, U0, Uk, s0, s1.
// * KtgfSsprkStageCells: the same stage with the cell fields and source computed from Uk by a cell program
//   (ktgf.solver.cell_program, registered by key with KtgfRegisterCells) plane by plane as the sweep goes
//   (sweep_fused), so they never go to memory (1.3x faster per stage at 64^3 than writing them first).
// * KtgfCellLimits: the maxima of a step-start program's terms (step limits, state checks) at a state.
// The padded fields (two periodic ghost cells per side) are swept in blocks of ROW_BLOCK rows so that the
// five planes a stencil reaches stay in L2 (1.3x faster at 64^3 than whole planes); each cell's MUSCL
// slope along an axis is kept for its second face.
//
// Build: one library per variant (flux_kernel.py, Variant), selected by -DKTGF_REAL=double|float,
// -DKTGF_LIMITER and -DKTGF_RIEMANN (indices of stencil.LIMITERS, RIEMANN_SOLVERS) and -DKTGF_KIND (below);
// its handlers refuse (InvalidArgument) a call for another variant.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <mutex>
#include <string>
#include <thread>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

#include "xla/ffi/api/ffi.h"
#ifdef _OPENMP
#include <omp.h>
#endif

namespace ffi = xla::ffi;

namespace {

enum Limiter { MINMOD = 0, VANLEER = 1, MC = 2, NONE = 3 };  // order of fluxes.LIMITERS
enum Riemann { HLL = 0, RUSANOV = 1 };                        // order of fluxes.RIEMANN_SOLVERS
enum Field { RHO, UX, UY, UZ, TH, PS, GG, ETA, LAM, KAP, OMG, NFIELD };
constexpr int GHOST = 2;
// Inlined into the row loops, which the compiler then vectorises along the contiguous axis.
#define KTGF_INLINE inline __attribute__((always_inline))

// min/max as compare-and-select (vectorisable; for the finite values here the same as jnp.minimum/maximum).
template <class T>
KTGF_INLINE T min2(T a, T b) { return a < b ? a : b; }
template <class T>
KTGF_INLINE T max2(T a, T b) { return a > b ? a : b; }

template <class T, int LIM>
KTGF_INLINE T slope(T dm, T dp) {  // fluxes.limited_slope
  if (LIM == NONE) return T(0.5) * (dm + dp);
  const T prod = dm * dp;
  if (LIM == VANLEER) return prod > T(0) ? T(2) * prod / (dm + dp) : T(0);
  const T adm = std::fabs(dm), adp = std::fabs(dp);
  T s;
  if (LIM == MINMOD) s = min2(adm, adp);
  else s = min2(min2(T(2) * adm, T(2) * adp), T(0.5) * std::fabs(dm + dp));
  return prod > T(0) ? (dm > T(0) ? s : -s) : T(0);
}

// Grid constants in the field precision, rounded from float64 as JAX rounds its Python floats.
template <class T>
struct Consts {
  long n[3];
  long stride[2];     // plane and row strides of the padded fields
  T inv_dx[3];        // 1/dx_a (normal derivatives, face divergence)
  T half_inv_dx[3];   // 0.5/dx_a (central derivatives)
  T omega_factor[3];  // (1/dx_a)/rho_s
  bool wrap2 = true;  // the ghost cells along z are periodic images (false: set by the caller, set_ghosts)
};

// Field f at the cell (i + d0, j + d1, q + d2) of the cell (i, j, q) at offset c of its plane, through a table of
// planes: P[(d0 + 1) * NFIELD + f] is field f of plane i + d0, padded with row stride s1 (sweep or sweep_fused).
template <class T>
struct Stencil {
  const T* const* P;
  long c, s1;
  KTGF_INLINE T operator()(int f, int d0, int d1, int d2) const { return P[(d0 + 1) * NFIELD + f][c + d1 * s1 + d2]; }
};

// Half MUSCL slopes along A of the fields 0..6 at the row's cells q = from .. to - 1 (fluxes.reconstruct),
// out[f * ld + q]: each cell's slope serves the two faces along A it touches, so it is computed once.
template <class T, int A, int LIM>
KTGF_INLINE void row_slopes(const T* const* P, long c0, const Consts<T>& k, T* out, long ld, long from, long to) {
  constexpr int e0 = A == 0, e1 = A == 1, e2 = A == 2;
  const long s1 = k.stride[1];
  #pragma GCC unroll 8
  for (int f = 0; f < 7; ++f) {
    T* o = out + f * ld;
#pragma omp simd
    for (long q = from; q < to; ++q) {
      const Stencil<T> X{P, c0 + q, s1};
      const T fm = X(f, -e0, -e1, -e2), f0 = X(f, 0, 0, 0), f1 = X(f, e0, e1, e2);
      o[q] = T(0.5) * slope<T, LIM>(f0 - fm, f1 - f0);
    }
  }
}

// Flux through the face between the cell (i, j, q) of the stencil and its neighbour along axis A: out[v * ld],
// from the half slopes hl[f * lh] of the cell and hr[f * lh] of its neighbour.
// The small loops are unrolled by pragma: a loop left inside stops the row loop from vectorising.
template <class T, int A, int RIE, bool VISC>
KTGF_INLINE void face_flux(const Stencil<T>& X, const T* hl, const T* hr, long lh, const Consts<T>& k, T* out, long ld) {
  constexpr int e0 = A == 0, e1 = A == 1, e2 = A == 2;  // unit step along A
  T WL[7], WR[7];
  #pragma GCC unroll 8
  for (int f = 0; f < 7; ++f) {  // fluxes.reconstruct: MUSCL left/right states
    WL[f] = X(f, 0, 0, 0) + hl[f * lh];
    WR[f] = X(f, e0, e1, e2) - hr[f * lh];
  }
  // fluxes.riemann_flux
  const T pL = WL[RHO] * WL[TH] * WL[PS], pR = WR[RHO] * WR[TH] * WR[PS];
  const T cL = std::sqrt(WL[TH] * WL[GG]), cR = std::sqrt(WR[TH] * WR[GG]);
  const T uL = WL[1 + A], uR = WR[1 + A];
  T UL[5], UR[5], FL[5], FR[5];
  UL[0] = WL[RHO];
  UR[0] = WR[RHO];
  #pragma GCC unroll 8
  for (int j = 0; j < 3; ++j) {
    UL[1 + j] = WL[RHO] * WL[1 + j];
    UR[1 + j] = WR[RHO] * WR[1 + j];
  }
  const T keL = T(0.5) * (WL[UX] * WL[UX] + WL[UY] * WL[UY] + WL[UZ] * WL[UZ]);
  const T keR = T(0.5) * (WR[UX] * WR[UX] + WR[UY] * WR[UY] + WR[UZ] * WR[UZ]);
  UL[4] = WL[RHO] * (keL + T(1.5) * WL[TH]);
  UR[4] = WR[RHO] * (keR + T(1.5) * WR[TH]);
  #pragma GCC unroll 8
  for (int v = 0; v < 4; ++v) {
    FL[v] = UL[v] * uL;
    FR[v] = UR[v] * uR;
  }
  FL[1 + A] += pL;
  FR[1 + A] += pR;
  FL[4] = (UL[4] + pL) * uL;
  FR[4] = (UR[4] + pR) * uR;
  T F[5];
  if (RIE == RUSANOV) {
    const T smax = max2(std::fabs(uL) + cL, std::fabs(uR) + cR);
    #pragma GCC unroll 8
    for (int v = 0; v < 5; ++v) F[v] = T(0.5) * (FL[v] + FR[v]) - T(0.5) * smax * (UR[v] - UL[v]);
  } else {  // HLL, Davis wave speeds
    const T sl = min2(min2(uL - cL, uR - cR), T(0));
    const T sr = max2(max2(uL + cL, uR + cR), T(0));
    const T inv = T(1) / (sr - sl);
    #pragma GCC unroll 8
    for (int v = 0; v < 5; ++v) F[v] = (sr * FL[v] - sl * FR[v] + sl * sr * (UR[v] - UL[v])) * inv;
  }
  if (VISC) {  // fluxes.viscous_flux: central stress and heat flux, face coefficients = cell means
    const T eta = T(0.5) * (X(ETA, 0, 0, 0) + X(ETA, e0, e1, e2));
    const T lam = T(0.5) * (X(LAM, 0, 0, 0) + X(LAM, e0, e1, e2));
    const T kap = T(0.5) * (X(KAP, 0, 0, 0) + X(KAP, e0, e1, e2));
    const T omg = T(0.5) * (X(OMG, 0, 0, 0) + X(OMG, e0, e1, e2));
    T grad[3][3];  // grad[b][j] = d u_j / d x_b at the face
    #pragma GCC unroll 8
    for (int b = 0; b < 3; ++b) {
      const int b0 = b == 0, b1 = b == 1, b2 = b == 2;
      #pragma GCC unroll 8
      for (int j = 0; j < 3; ++j) {
        if (b == A) {
          grad[b][j] = (X(UX + j, e0, e1, e2) - X(UX + j, 0, 0, 0)) * k.inv_dx[A];
        } else {
          const T g0 = (X(UX + j, b0, b1, b2) - X(UX + j, -b0, -b1, -b2)) * k.half_inv_dx[b];
          const T g1 = (X(UX + j, e0 + b0, e1 + b1, e2 + b2) - X(UX + j, e0 - b0, e1 - b1, e2 - b2)) * k.half_inv_dx[b];
          grad[b][j] = T(0.5) * (g0 + g1);
        }
      }
    }
    const T divu = grad[0][0] + grad[1][1] + grad[2][2];
    T tau[3];
    #pragma GCC unroll 8
    for (int j = 0; j < 3; ++j) tau[j] = eta * (grad[A][j] + grad[j][A]);
    tau[A] = tau[A] + (lam - T(2.0 / 3.0) * eta) * divu;
    const T q = -kap * (X(TH, e0, e1, e2) - X(TH, 0, 0, 0)) * k.inv_dx[A] -
                omg * (X(RHO, e0, e1, e2) - X(RHO, 0, 0, 0)) * k.omega_factor[A];
    T work = T(0);
    #pragma GCC unroll 8
    for (int j = 0; j < 3; ++j)
      work = work + tau[j] * (T(0.5) * (X(UX + j, 0, 0, 0) + X(UX + j, e0, e1, e2)));
    F[1] = F[1] + -tau[0];
    F[2] = F[2] + -tau[1];
    F[3] = F[3] + -tau[2];
    F[4] = F[4] + (q - work);
  }
  #pragma GCC unroll 8
  for (int v = 0; v < 5; ++v) out[v * ld] = F[v];
}

// What a sweep writes per row: -div F and div u (Rhs), or the SSP-RK3 stage state (Stage).
template <class T>
struct Rhs {
  T* dU[5];
  T* divu;
};
// What a stage writes: U' = a U0 + b (Uk + dt L).
template <class T>
struct Stage {
  const T* U0[5];
  const T* Uk[5];
  const T* s0;  // energy source = s0 + s1 div u
  const T* s1;
  T a, b, dt;   // U' = a U0 + b (Uk + dt L), b = 1 - a
  T g[3];       // the body force per unit mass: L gains rho g (momentum) and g . (rho u) (energy), from Uk
  bool gravity;  // g != 0
  const T* fix;  // boundary corrections of L (fix_row), or nullptr
  int fix_axis;
  T* U[5];
};

// Face fluxes along A of the row starting at padded cell c0: the faces between q and its
// neighbour along A, q = from .. n2 - 1, into out[q + v * ld]; hl, hr the half slopes of the two cells (index q).
template <class T, int A, int RIE, bool VISC>
KTGF_INLINE void row_faces(const T* const* P, long c0, const Consts<T>& k, const T* hl, const T* hr, long lh, T* out,
                           long ld, long from = 0) {
  const long n2 = k.n[2], s1 = k.stride[1];
#pragma omp simd
  for (long q = from; q < n2; ++q)
    face_flux<T, A, RIE, VISC>(Stencil<T>{P, c0 + q, s1}, hl + q, hr + q, lh, k, out + q, ld);
}

// Central div u of the row's cells.
template <class T>
KTGF_INLINE void row_divu(const T* const* P, long c0, const Consts<T>& k, T* dv) {
  const long n2 = k.n[2], s1 = k.stride[1];
#pragma omp simd
  for (long q = 0; q < n2; ++q) {
    const Stencil<T> X{P, c0 + q, s1};
    dv[q] = (X(UX, 1, 0, 0) - X(UX, -1, 0, 0)) * k.half_inv_dx[0] +
            (X(UY, 0, 1, 0) - X(UY, 0, -1, 0)) * k.half_inv_dx[1] +
            (X(UZ, 0, 0, 1) - X(UZ, 0, 0, -1)) * k.half_inv_dx[2];
  }
}

// The fields with GHOST periodic ghost cells per side of every axis.
template <class T>
void pad(const T* const* in, int nfield, const long* n, T* work) {
  const long m0 = n[0] + 2 * GHOST, m1 = n[1] + 2 * GHOST, m2 = n[2] + 2 * GHOST;
#pragma omp parallel for collapse(2) schedule(static)
  for (int f = 0; f < nfield; ++f) {
    for (long i = 0; i < m0; ++i) {
      const long si = (i - GHOST + n[0]) % n[0];
      for (long j = 0; j < m1; ++j) {
        const long sj = (j - GHOST + n[1]) % n[1];
        const T* src = in[f] + (si * n[1] + sj) * n[2];
        T* dst = work + ((f * m0 + i) * m1 + j) * m2;
        for (long q = 0; q < GHOST; ++q) {
          dst[q] = src[n[2] - GHOST + q];
          dst[GHOST + n[2] + q] = src[q];
        }
        for (long q = 0; q < n[2]; ++q) dst[GHOST + q] = src[q];
      }
    }
  }
}

// Overwrites the ghost planes along `axis` of the periodically padded fields in `work` with `ghost`: per field, the
// GHOST planes below the grid then the GHOST above it, each of the padded shape of the other two axes in order
// (the boundary conditions of a wall or Lees-Edwards axis, filled by the caller).
template <class T>
void set_ghosts(const T* ghost, int nfield, const long* n, int axis, T* work) {
  const long m[3] = {n[0] + 2 * GHOST, n[1] + 2 * GHOST, n[2] + 2 * GHOST};
  const long stride[3] = {m[1] * m[2], m[2], 1};
  const int b = axis == 0 ? 1 : 0, c = axis == 2 ? 1 : 2;
#pragma omp parallel for collapse(3) schedule(static)
  for (int f = 0; f < nfield; ++f) {
    for (int side = 0; side < 2; ++side) {
      for (long q = 0; q < GHOST; ++q) {
        const T* src = ghost + ((f * 2 + side) * GHOST + q) * m[b] * m[c];
        T* dst = work + f * m[0] * stride[0] + (side ? n[axis] + GHOST + q : q) * stride[axis];
        for (long i = 0; i < m[b]; ++i)
          for (long j = 0; j < m[c]; ++j) dst[i * stride[b] + j * stride[c]] = src[i * m[c] + j];
      }
    }
  }
}

// -div F of field v at the row's cells from the face fluxes below (xl, yl, z[q]) and above (xh, yh, z[q + 1]).
template <class T>
KTGF_INLINE T cell_div(const T* xl, const T* xh, const T* yl, const T* yh, const T* z, long q, const Consts<T>& k) {
  T d = (xl[q] - xh[q]) * k.inv_dx[0];
  d = d + (yl[q] - yh[q]) * k.inv_dx[1];
  return d + (z[q] - z[q + 1]) * k.inv_dx[2];
}

template <class T>
KTGF_INLINE void write_row(const Rhs<T>& o, const T* const* P, long c0, long out, const Consts<T>& k,
                           const T* const* lo, const T* const* hi, const T* z, long zld, T* /*scratch*/,
                           const T* /*s0*/, const T* /*s1*/) {
  const long n2 = k.n[2];
  for (int v = 0; v < 5; ++v) {
    T* d = o.dU[v] + out;
    const T* zv = z + v * zld;
#pragma omp simd
    for (long q = 0; q < n2; ++q) d[q] = cell_div(lo[v], hi[v], lo[5 + v], hi[5 + v], zv, q, k);
  }
  row_divu(P, c0, k, o.divu + out);
}

// Field v of a stage's output row at offset `out` (write_row); SRC: with the energy source s0 + s1 div u (the
// energy row); G: with the body force, rho g_v on a momentum row (v = 1, 2, 3) or its power g . (rho u) on the energy row.
template <class T, bool SRC, bool G>
KTGF_INLINE void stage_row(const Stage<T>& o, int v, long out, const Consts<T>& k, const T* lo, const T* hi,
                           const T* ylo, const T* yhi, const T* zv, const T* divu, const T* s0, const T* s1) {
  const long n2 = k.n[2];
  const T* u0 = o.U0[v] + out;
  const T* uk = o.Uk[v] + out;
  const T *rho = o.Uk[0] + out, *m0 = o.Uk[1] + out, *m1 = o.Uk[2] + out, *m2 = o.Uk[3] + out;
  const T gv = G && !SRC ? o.g[v - 1] : T(0);
  T* d = o.U[v] + out;
#pragma omp simd
  for (long q = 0; q < n2; ++q) {
    T L = cell_div(lo, hi, ylo, yhi, zv, q, k);
    if (SRC) L = L + (s0[q] + s1[q] * divu[q]);
    if (G) L = L + (SRC ? o.g[0] * m0[q] + o.g[1] * m1[q] + o.g[2] * m2[q] : gv * rho[q]);
    d[q] = o.a * u0[q] + o.b * (uk[q] + o.dt * L);
  }
}

// The five output rows, energy first and density last: U' may be written over Uk, and the body force reads the
// momentum (energy row) and the density (momentum rows) of Uk.
template <class T, bool G>
KTGF_INLINE void stage_rows(const Stage<T>& o, long out, const Consts<T>& k, const T* const* lo, const T* const* hi,
                            const T* z, long zld, const T* divu, const T* s0, const T* s1) {
  stage_row<T, true, G>(o, 4, out, k, lo[4], hi[4], lo[9], hi[9], z + 4 * zld, divu, s0, s1);
  for (int v = 1; v < 4; ++v)
    stage_row<T, false, G>(o, v, out, k, lo[v], hi[v], lo[5 + v], hi[5 + v], z + v * zld, divu, s0, s1);
  stage_row<T, false, false>(o, 0, out, k, lo[0], hi[0], lo[5], hi[5], z, divu, s0, s1);
}

// Adds b dt x the boundary corrections o.fix to the output row at offset `out`, after it is written, as the JAX
// path adds them (fluxes.add_boundary_fluxes): o.fix holds 2 ends x 5 fields of the planes next to each end of the
// axis o.fix_axis (the cells 0 and n - 1 along it), each a plane of the other two axes in C order.
template <class T>
KTGF_INLINE void fix_row(const Stage<T>& o, long out, const Consts<T>& k) {
  const long n1 = k.n[1], n2 = k.n[2];
  const long i = out / (n1 * n2), j = (out / n2) % n1;
  const int a = o.fix_axis;
  const long np = a == 0 ? n1 * n2 : a == 1 ? k.n[0] * n2 : k.n[0] * n1;
  const T w = o.b * o.dt;
  for (int s = 0; s < 2; ++s) {
    const T* f = o.fix + s * 5 * np;
    if (a == 2) {  // one cell of the row
      const long q = s ? n2 - 1 : 0, at = i * n1 + j;
      for (int v = 0; v < 5; ++v) o.U[v][out + q] = o.U[v][out + q] + w * f[v * np + at];
    } else if ((a == 0 ? i : j) == (s ? k.n[a] - 1 : 0)) {  // the whole row
      const long at = (a == 0 ? j : i) * n2;
      for (int v = 0; v < 5; ++v) {
        T* d = o.U[v] + out;
        const T* c = f + v * np + at;
#pragma omp simd
        for (long q = 0; q < n2; ++q) d[q] = d[q] + w * c[q];
      }
    }
  }
}

template <class T>
KTGF_INLINE void write_row(const Stage<T>& o, const T* const* P, long c0, long out, const Consts<T>& k,
                           const T* const* lo, const T* const* hi, const T* z, long zld, T* divu, const T* s0,
                           const T* s1) {
  row_divu(P, c0, k, divu);
  if (o.gravity)
    stage_rows<T, true>(o, out, k, lo, hi, z, zld, divu, s0, s1);
  else
    stage_rows<T, false>(o, out, k, lo, hi, z, zld, divu, s0, s1);
  if (o.fix) fix_row(o, out, k);
}

// The energy source rows of the output at offset `out` (a stage's s0, s1; none for Rhs).
template <class T>
KTGF_INLINE void source_rows(const Rhs<T>&, long, const T** s) { s[0] = s[1] = nullptr; }
template <class T>
KTGF_INLINE void source_rows(const Stage<T>& o, long out, const T** s) {
  s[0] = o.s0 + out;
  s[1] = o.s1 + out;
}

constexpr long ROW_BLOCK = 16;

// The per-thread buffers of a sweep over rows of n2 cells with B rows in flight: the faces and half slopes
// along x of B rows on the plane being swept (xlo, hx) and the next (xhi, hxn), which trade places after each
// plane; along y of a row and the next (ylo/hya, yhi/hyb), which trade after each row; along z of a row; div u.
template <class T>
struct RowBuffers {
  long B, n2;
  std::vector<T> xlo, xhi, ylo, yhi, zf, divu, hx, hxn, hya, hyb, hz;
  RowBuffers(long B_, long n2_)
      : B(B_), n2(n2_), xlo(5 * B_ * n2_), xhi(5 * B_ * n2_), ylo(5 * n2_), yhi(5 * n2_), zf(5 * (n2_ + 1)),
        divu(n2_), hx(7 * B_ * n2_), hxn(7 * B_ * n2_), hya(7 * n2_), hyb(7 * n2_), hz(7 * (n2_ + 2)) {}
};

// The lower x faces of rows b = 0 .. nb - 1 of a block: the half x slopes of the plane below (table Pm) and of
// the block's plane (table P0), and the faces between them; rows at in-plane offsets row(b).
template <class T, int LIM, int RIE, bool VISC, class Row>
KTGF_INLINE void start_block(const T* const* Pm, const T* const* P0, long nb, Row row, const Consts<T>& k,
                             RowBuffers<T>& r) {
  const long n2 = k.n[2];
  for (long b = 0; b < nb; ++b) {
    row_slopes<T, 0, LIM>(Pm, row(b), k, r.hxn.data() + b * 7 * n2, n2, 0, n2);
    row_slopes<T, 0, LIM>(P0, row(b), k, r.hx.data() + b * 7 * n2, n2, 0, n2);
    row_faces<T, 0, RIE, VISC>(Pm, row(b), k, r.hxn.data() + b * 7 * n2, r.hx.data() + b * 7 * n2, n2,
                               r.xlo.data() + b * n2, r.B * n2);
  }
}

// Rows b = 0 .. nb - 1 of plane i (table P0; P1 the table of plane i + 1, whose x slopes are computed here):
// the faces above each row along x and y and the z faces, and the row's output (o, row b at output offset
// out(b), energy source rows src(b)); row(b) the in-plane offsets, row(-1) that of the row below the first.
template <class T, int LIM, int RIE, bool VISC, class Out, class Row, class OutRow, class Src>
KTGF_INLINE void sweep_rows(const T* const* P0, const T* const* P1, long nb, Row row, OutRow out, Src src,
                            const Consts<T>& k, const Out& o, RowBuffers<T>& r) {
  const long n2 = k.n[2], B = r.B;
  T* hy = r.hya.data();
  T* hyn = r.hyb.data();
  T* ylo = r.ylo.data();
  T* yhi = r.yhi.data();
  row_slopes<T, 1, LIM>(P0, row(-1), k, hyn, n2, 0, n2);
  row_slopes<T, 1, LIM>(P0, row(0), k, hy, n2, 0, n2);
  row_faces<T, 1, RIE, VISC>(P0, row(-1), k, hyn, hy, n2, ylo, n2);
  for (long b = 0; b < nb; ++b) {
    const long c0 = row(b);
    T* hxb = r.hx.data() + b * 7 * n2;
    T* hxnb = r.hxn.data() + b * 7 * n2;
    row_slopes<T, 0, LIM>(P1, c0, k, hxnb, n2, 0, n2);
    row_faces<T, 0, RIE, VISC>(P0, c0, k, hxb, hxnb, n2, r.xhi.data() + b * n2, B * n2);
    row_slopes<T, 1, LIM>(P0, row(b + 1), k, hyn, n2, 0, n2);
    row_faces<T, 1, RIE, VISC>(P0, c0, k, hy, hyn, n2, yhi, n2);
    // z: the n2 slopes and faces of the row's own cells, then the periodic images (the slopes of cells -1 and n2,
    // the face below cell 0): the same inputs, so the same bits, and a whole number of vectors (no scalar tail).
    T* hz = r.hz.data() + 1;
    T* zf = r.zf.data() + 1;
    if (k.wrap2) {
      row_slopes<T, 2, LIM>(P0, c0, k, hz, n2 + 2, 0, n2);
      for (int f = 0; f < 7; ++f) {
        hz[f * (n2 + 2) - 1] = hz[f * (n2 + 2) + n2 - 1];
        hz[f * (n2 + 2) + n2] = hz[f * (n2 + 2)];
      }
      row_faces<T, 2, RIE, VISC>(P0, c0, k, hz, hz + 1, n2 + 2, zf, n2 + 1, 0);
      for (int v = 0; v < 5; ++v) zf[v * (n2 + 1) - 1] = zf[v * (n2 + 1) + n2 - 1];
    } else {  // the ghost cells' slopes and the face below cell 0 from the padded fields themselves
      row_slopes<T, 2, LIM>(P0, c0, k, hz, n2 + 2, -1, n2 + 1);
      row_faces<T, 2, RIE, VISC>(P0, c0, k, hz, hz + 1, n2 + 2, zf, n2 + 1, -1);
    }
    const T* lo[10];
    const T* hi[10];
    for (int v = 0; v < 5; ++v) {
      lo[v] = r.xlo.data() + v * B * n2 + b * n2;
      hi[v] = r.xhi.data() + v * B * n2 + b * n2;
      lo[5 + v] = ylo + v * n2;
      hi[5 + v] = yhi + v * n2;
    }
    const T* s[2];
    src(b, s);
    write_row(o, P0, c0, out(b), k, lo, hi, r.zf.data(), n2 + 1, r.divu.data(), s[0], s[1]);
    std::swap(hy, hyn);  // the upper y faces and slopes become the next row's lower ones
    std::swap(ylo, yhi);
  }
  std::swap(r.xlo, r.xhi);  // the upper x faces and slopes become the next plane's lower ones
  std::swap(r.hx, r.hxn);
}

// The table of planes p - 1, p, p + 1 (p from -1 to n0) of the padded fields P (stride s0 between planes).
template <class T>
KTGF_INLINE void plane_table(const T* const* P, int nfield, long s0, long p, const T** table) {
  for (int d = 0; d < 3; ++d)
    for (int f = 0; f < NFIELD; ++f) table[d * NFIELD + f] = f < nfield ? P[f] + (p - 1 + d + GHOST) * s0 : nullptr;
}

// Sweep of padded fields (all planes in memory, `P` the NFIELD fields, or GG + 1 without the transport).
// Each thread owns a block of planes and sweeps them row block by row block, keeping the lower x and y faces
// and half slopes from the previous plane and row, so each is computed once (plus one plane and row per block).
template <class T, int LIM, int RIE, bool VISC, class Out>
void sweep(const T* const* P, const Consts<T>& k, const Out& o) {
  const long n0 = k.n[0], n1 = k.n[1], n2 = k.n[2], s0 = k.stride[0], s1 = k.stride[1];
  const int nfield = VISC ? NFIELD : GG + 1;
#pragma omp parallel
  {
    const long B = ROW_BLOCK < n1 ? ROW_BLOCK : n1;
    RowBuffers<T> r(B, n2);
    int nt = 1, t = 0;
#ifdef _OPENMP
    nt = omp_get_num_threads();
    t = omp_get_thread_num();
#endif
    const long i0 = n0 * t / nt, i1 = n0 * (t + 1) / nt;
    const T* Pm[3 * NFIELD];
    const T* P0[3 * NFIELD];
    const T* P1[3 * NFIELD];
    for (long jb = 0; jb < n1 && i0 < i1; jb += B) {
      const long je = jb + B < n1 ? jb + B : n1;
      auto row = [&](long b) { return (jb + b + GHOST) * s1 + GHOST; };
      plane_table(P, nfield, s0, i0 - 1, Pm);
      plane_table(P, nfield, s0, i0, P0);
      start_block<T, LIM, RIE, VISC>(Pm, P0, je - jb, row, k, r);
      for (long i = i0; i < i1; ++i) {
        plane_table(P, nfield, s0, i, P0);
        plane_table(P, nfield, s0, i + 1, P1);
        const long out0 = (i * n1 + jb) * n2;
        sweep_rows<T, LIM, RIE, VISC>(P0, P1, je - jb, row, [&](long b) { return out0 + b * n2; },
                                      [&](long b, const T** s) { source_rows(o, out0 + b * n2, s); }, k, o, r);
      }
    }
  }
}

// The kind of library (flux_kernel.py, KINDS); each instantiates `sweep` once, most of a build's 7-15 s.
#define KTGF_RHS 0    // KtgfFluxDivergence with the viscous fluxes
#define KTGF_EULER 1  // KtgfFluxDivergence without them
#define KTGF_STAGE 2  // KtgfSsprkStage, KtgfSsprkStageCells, KtgfCellLimits, KtgfRegisterCells, KtgfRingElements
#if !defined(KTGF_REAL) || !defined(KTGF_LIMITER) || !defined(KTGF_RIEMANN) || !defined(KTGF_KIND)
#error "build with -DKTGF_REAL=double|float -DKTGF_LIMITER=0..3 -DKTGF_RIEMANN=0..1 -DKTGF_KIND=0..2 (flux_kernel.py)"
#endif
static_assert(KTGF_KIND == KTGF_RHS || KTGF_KIND == KTGF_EULER || KTGF_KIND == KTGF_STAGE, "KTGF_KIND: 0..2");
using Real = KTGF_REAL;
static_assert(std::is_same<Real, double>::value || std::is_same<Real, float>::value, "KTGF_REAL: double or float");
static_assert(KTGF_LIMITER >= MINMOD && KTGF_LIMITER <= NONE, "KTGF_LIMITER: an index of fluxes.LIMITERS");
static_assert(KTGF_RIEMANN == HLL || KTGF_RIEMANN == RUSANOV, "KTGF_RIEMANN: an index of fluxes.RIEMANN_SOLVERS");
constexpr ffi::DataType BUILT_TYPE = std::is_same<Real, double>::value ? ffi::F64 : ffi::F32;
constexpr bool BUILT_VISCOUS = KTGF_KIND != KTGF_EULER;

std::string variant_name(ffi::DataType type, int limiter, int riemann, bool viscous) {
  static const char* const limiters[] = {"minmod", "vanleer", "mc", "none"};  // fluxes.LIMITERS
  static const char* const riemanns[] = {"hll", "rusanov"};                   // fluxes.RIEMANN_SOLVERS
  const std::string lim = limiter >= 0 && limiter <= NONE ? limiters[limiter] : "limiter " + std::to_string(limiter);
  const std::string rie = riemann >= 0 && riemann <= RUSANOV ? riemanns[riemann] : "riemann " + std::to_string(riemann);
  const char* precision = type == ffi::F64 ? "float64" : type == ffi::F32 ? "float32" : "a non-float type";
  return std::string(precision) + " " + lim + "/" + rie + (viscous ? " viscous" : " inviscid");
}

// Success if a call of `entry` asks for the variant this library computes, else the error that says both.
ffi::Error check_variant(const char* entry, ffi::DataType type, int limiter, int riemann, bool viscous) {
  if (type == BUILT_TYPE && limiter == KTGF_LIMITER && riemann == KTGF_RIEMANN && viscous == BUILT_VISCOUS)
    return ffi::Error::Success();
  return ffi::Error::InvalidArgument(std::string(entry) + ": this library is built for " +
                                     variant_name(BUILT_TYPE, KTGF_LIMITER, KTGF_RIEMANN, BUILT_VISCOUS) +
                                     ", the call asks for " + variant_name(type, limiter, riemann, viscous));
}

// The grid constants of an (n0, n1, n2) grid with float64 params (dx, dy, dz, rho_s, ...), strides of padded fields.
Consts<Real> consts(const long* n, const double* params) {
  Consts<Real> k;
  for (int a = 0; a < 3; ++a) k.n[a] = n[a];
  k.stride[0] = (n[1] + 2 * GHOST) * (n[2] + 2 * GHOST);
  k.stride[1] = n[2] + 2 * GHOST;
  const double rho_s = params[3];
  for (int a = 0; a < 3; ++a) {
    k.inv_dx[a] = Real(1.0 / params[a]);
    k.half_inv_dx[a] = Real(0.5 / params[a]);
    k.omega_factor[a] = Real((1.0 / params[a]) / rho_s);
  }
  return k;
}

// The grid shape of a 3D cell field, or an error.
ffi::Error grid_shape(const ffi::AnyBuffer& field, long* n) {
  auto dims = field.dimensions();
  if (dims.size() != 3) return ffi::Error::InvalidArgument("flux kernel: fields must be 3D");
  for (int a = 0; a < 3; ++a) n[a] = long(dims[a]);
  if (n[0] < GHOST || n[1] < GHOST || n[2] < GHOST)
    return ffi::Error::InvalidArgument("flux kernel: at least 2 cells per axis");
  return ffi::Error::Success();
}

// Checks that the `count` RemainingArgs from `from` on are cell fields of one precision and shape; their type in `type`.
ffi::Error same_fields(ffi::RemainingArgs state, size_t count, ffi::DataType& type, size_t from = 0) {
  if (state.size() < from + count) return ffi::Error::InvalidArgument("flux kernel: too few fields");
  auto first = state.get<ffi::AnyBuffer>(from);
  if (!first.has_value()) return ffi::Error::InvalidArgument("flux kernel: no fields");
  type = first->element_type();
  for (size_t i = from; i < from + count; ++i) {
    auto b = state.get<ffi::AnyBuffer>(i);
    if (!b.has_value() || b->element_type() != type || b->element_count() != first->element_count())
      return ffi::Error::InvalidArgument("flux kernel: the fields must be cell fields of one precision");
  }
  return ffi::Error::Success();
}

// The ghost planes (set_ghosts) along the axis params[naxis] that `in` holds as its argument nin, if it has more
// than nin arguments (else ghost = nullptr, axis = -1), checked against the grid n and nfield fields.
ffi::Error ghost_planes(ffi::RemainingArgs in, size_t nin, const double* params, size_t naxis, int nfield,
                        const long* n, const Real*& ghost, int& axis) {
  ghost = nullptr;
  axis = -1;
  if (in.size() <= nin) return ffi::Error::Success();
  axis = int(params[naxis]);
  auto g = in.get<ffi::AnyBuffer>(nin);
  const int b = axis == 0 ? 1 : 0, c = axis == 2 ? 1 : 2;
  const long planes = nfield * 2 * GHOST * (n[b] + 2 * GHOST) * (n[c] + 2 * GHOST);
  if (axis < 0 || axis > 2 || !g.has_value() || long(g->element_count()) != planes ||
      g->element_type() != in.get<ffi::AnyBuffer>(0)->element_type())
    return ffi::Error::InvalidArgument("flux kernel: ghost planes = fields x 2 x GHOST planes of the padded shape of "
                                       "the other axes, in the fields' precision, axis 0..2");
  ghost = g->typed_data<Real>();
  return ffi::Error::Success();
}

// Sweeps the cell fields (the first NFIELD of `in`, of the grid's shape) on the grid of the output field `grid` with
// the output `o` (Rhs or Stage), padded periodically into `work` first, then with the ghost planes of `in` after
// its first nin arguments, if any (ghost_planes: walls, Lees-Edwards).
template <class Out>
ffi::Error run(ffi::RemainingArgs in, size_t nin, const ffi::AnyBuffer& grid, const double* params, size_t naxis,
               Real* work, const Out& o) {
  long n[3], m[3];
  if (auto err = grid_shape(grid, n); err.failure()) return err;
  if (auto err = grid_shape(*in.get<ffi::AnyBuffer>(0), m); err.failure()) return err;
  if (m[0] != n[0] || m[1] != n[1] || m[2] != n[2])
    return ffi::Error::InvalidArgument("flux kernel: the cell fields must have the grid's shape");
  const int nfield = BUILT_VISCOUS ? NFIELD : GG + 1;
  const Real* ghost;
  int axis;
  if (auto err = ghost_planes(in, nin, params, naxis, nfield, n, ghost, axis); err.failure()) return err;
  std::vector<const Real*> fields(NFIELD, nullptr);
  for (int f = 0; f < nfield; ++f) fields[f] = in.get<ffi::AnyBuffer>(f)->typed_data<Real>();
  pad<Real>(fields.data(), nfield, n, work);
  if (ghost) set_ghosts<Real>(ghost, nfield, n, axis, work);
  Consts<Real> k = consts(n, params);
  k.wrap2 = axis != 2;
  const long M = (n[0] + 2 * GHOST) * k.stride[0];
  for (int f = 0; f < nfield; ++f) fields[f] = work + f * M;  // the padded fields, swept
  sweep<Real, KTGF_LIMITER, KTGF_RIEMANN, BUILT_VISCOUS>(fields.data(), k, o);
  return ffi::Error::Success();
}

#if KTGF_KIND != KTGF_STAGE
ffi::Error flux_divergence(ffi::Buffer<ffi::F64> params, ffi::RemainingArgs in, int32_t limiter, int32_t riemann,
                           int32_t viscous, ffi::Result<ffi::AnyBuffer> d0, ffi::Result<ffi::AnyBuffer> d1,
                           ffi::Result<ffi::AnyBuffer> d2, ffi::Result<ffi::AnyBuffer> d3,
                           ffi::Result<ffi::AnyBuffer> d4, ffi::Result<ffi::AnyBuffer> divu,
                           ffi::Result<ffi::AnyBuffer> work) {
  const bool ghosts = in.size() == NFIELD + 1;
  if (params.element_count() != 4 + ghosts)
    return ffi::Error::InvalidArgument("flux kernel: params = (dx, dy, dz, rho_s[, ghost axis])");
  if (in.size() != NFIELD + ghosts)
    return ffi::Error::InvalidArgument("flux kernel: fields = the 11 cell fields[, ghost planes]");
  ffi::DataType type;
  if (auto err = same_fields(in, NFIELD, type); err.failure()) return err;
  if (auto err = check_variant("KtgfFluxDivergence", type, limiter, riemann, viscous != 0); err.failure()) return err;
  const Rhs<Real> o{{d0->typed_data<Real>(), d1->typed_data<Real>(), d2->typed_data<Real>(), d3->typed_data<Real>(),
                     d4->typed_data<Real>()},
                    divu->typed_data<Real>()};
  return run(in, NFIELD, *d0, params.typed_data(), 4, work->typed_data<Real>(), o);
}
#else  // the stage kind
// Cell programs (ktgf.solver.cell_program), by key: f(n, params, in[5], out[NFIELD + 2 + nlim]) over n cells,
// in = the conservative fields, out = the NFIELD cell fields, then s0, s1, then (a step-start program) the
// nlim cell terms whose maxima give the step limits.
struct CellProgram {
  void* fn;
  int bits;  // 32 or 64: the state precision it was generated for
};
std::mutex programs_mutex;
std::unordered_map<int64_t, CellProgram> programs;

template <class T>
using CellsFn = void (*)(long, const double*, const T* const*, T* const*);

// max as jnp.max: a NaN wins (so a NaN step limit reaches the step's status check).
template <class T>
KTGF_INLINE T max_nan(T m, T x) { return (x > m || x != x) ? x : m; }

// Merges the maxima of a row of n cells of the nlim terms t[k] into local[k]: a NaN wins, as in jnp.max.
template <class T>
KTGF_INLINE void row_maxima(T* const* t, long n, int nlim, T* local) {
  for (int k = 0; k < nlim; ++k) {  // the row's maximum and whether it holds a NaN: a vector loop
    const T* r = t[k];
    T m = local[k];
    if (m != m) continue;  // a NaN already: it stays
    int nan = 0;
#pragma omp simd reduction(max : m) reduction(| : nan)
    for (long q = 0; q < n; ++q) {
      m = r[q] > m ? r[q] : m;
      nan |= r[q] != r[q];
    }
    local[k] = nan ? std::numeric_limits<T>::quiet_NaN() : m;
  }
}

// The maxima over the cells of the `nlim` limit terms of a step-start cell program fn on the state U, in one
// pass that writes nothing per cell (the cell fields go to a row scratch).  A NaN term wins, as in jnp.max.
template <class T>
void cell_limits(CellsFn<T> fn, const double* leaf, const T* const* U, const long* n, int nlim, T* maxima) {
  for (int k = 0; k < nlim; ++k) maxima[k] = -std::numeric_limits<T>::infinity();
#pragma omp parallel
  {
    std::vector<T> scratch(size_t(NFIELD + 2 + nlim) * n[2]), local(nlim, -std::numeric_limits<T>::infinity());
    std::vector<T*> out(NFIELD + 2 + nlim);
    for (int f = 0; f < NFIELD + 2 + nlim; ++f) out[f] = scratch.data() + f * n[2];
#pragma omp for collapse(2) schedule(static)
    for (long i = 0; i < n[0]; ++i) {
      for (long j = 0; j < n[1]; ++j) {
        const T* in[5];
        for (int v = 0; v < 5; ++v) in[v] = U[v] + (i * n[1] + j) * n[2];
        fn(n[2], leaf, in, out.data());
        row_maxima(out.data() + NFIELD + 2, n[2], nlim, local.data());
      }
    }
#pragma omp critical(ktgf_cell_limits)
    for (int k = 0; k < nlim; ++k) maxima[k] = max_nan(maxima[k], local[k]);
  }
}

// The fused stage's ring: planes i - 1 .. i + 2 of the cell fields (NFIELD, then the energy source s0, s1)
// around the plane i being swept, in RING rolling slots, plus two slots that keep planes 0 and 1.
constexpr int RING = 4;
constexpr int NRING = NFIELD + 2;
// Fewest rows a thread of the fused sweep owns: each thread also evaluates the closures of 2 GHOST rows
// around its own, so more threads than n1 / MIN_ROWS would spend more on those than they gain.
constexpr long MIN_ROWS = 4;

// The threads the fused sweep uses on an (n0, n1, n2) grid.
inline int fused_threads(const long* n) {
  int nt = 1;
#ifdef _OPENMP
  nt = omp_get_max_threads();
#endif
  const long most = n[1] / MIN_ROWS > 1 ? n[1] / MIN_ROWS : 1;
  return int(nt < most ? nt : most);
}

// Elements of the ring of one of nthreads threads (its n1 / nthreads rows rounded up, with ghost rows).
inline long ring_size(const long* n, int nthreads) {
  const long rows = (n[1] + nthreads - 1) / nthreads + 2 * GHOST;
  return long(NRING) * (RING + 2) * rows * (n[2] + 2 * GHOST);
}

// Elements of the workspace of the fused sweep (the rings of its threads).
inline long ring_elements(const long* n) { return fused_threads(n) * ring_size(n, fused_threads(n)); }

// How far each thread of the fused sweep has got: the last plane whose cell fields it has computed; one
// cache line each, so that the spinning reads of one thread do not slow the writes of another.
struct alignas(64) Progress {
  std::atomic<long> placed;
};

// Tells the core that this thread is spinning (x86 pause, ARM yield): the other hyperthread gets the core, and
// leaving the loop does not flush the pipeline.  Other processors: nothing.
inline void spin_hint() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__) || defined(__arm__)
  asm volatile("yield" ::: "memory");
#endif
}

// Waits until the neighbours of thread t (of nt; whose ghost rows are t's rows) have computed the cell fields of
// plane p.  A spin: the wait is short, and a barrier per plane left 18 % of a 64^3 step idle (PASSIVE wake-ups).
inline void wait_for(const Progress* progress, int t, int nt, long p) {
  for (int d : {-1, 1}) {
    const int u = (t + d + nt) % nt;
    for (long spins = 0; progress[u].placed.load(std::memory_order_acquire) < p; ++spins) {
      if (spins < 4096) spin_hint();
      else std::this_thread::yield();  // the other thread's core may have been taken by the host
    }
  }
}

// One SSP-RK3 stage whose cell fields the cell program fn (parameters leaf) computes from Uk as the sweep goes:
// thread t owns rows [jlo, jhi) of every plane and keeps planes i - 1 .. i + 2 of them, with GHOST rows per
// side, in its ring (a slice of `ring_all`); before it sweeps plane i it computes plane i + 2 into the slot of
// plane i - 2 (planes 0 and 1, needed again at the end, keep their own slots).  U' may be written over Uk: a
// thread reads Uk of plane p before it writes U' of plane p, and then only once its neighbours have computed
// plane p (wait_for); or over U0, read only at the cell being written.  A boundary along y (gaxis 1) or z (2):
// the ghost cells' fields are the caller's `ghost` planes (set_ghosts), not the program's.
// Returns false (nothing computed) if the threads' rings do not fit in `capacity`.
template <class T, int LIM, int RIE>
bool sweep_fused(CellsFn<T> fn, const double* leaf, const Consts<T>& kg, const Stage<T>& o, T* ring_all,
                 long capacity, const T* ghost = nullptr, int gaxis = -1) {
  const long n0 = kg.n[0], n1 = kg.n[1], n2 = kg.n[2], m2 = kg.stride[1];
  bool fits = true;
  const int threads = fused_threads(kg.n);
  // Whether U' is written over what the neighbours read for their ghost rows (Uk): only then does a thread wait
  // for them before it writes a plane.
  bool shared = false;
  for (int v = 0; v < 5; ++v) shared = shared || o.U[v] == o.Uk[v];
  std::vector<Progress> progress(threads);
  for (auto& p : progress) p.placed.store(-3, std::memory_order_relaxed);
#pragma omp parallel num_threads(threads)
  {
    int nt = 1, t = 0;
#ifdef _OPENMP
    nt = omp_get_num_threads();
    t = omp_get_thread_num();
#endif
    const long per = capacity / nt;  // the same in every thread: all take the same branch
    if (per < ring_size(kg.n, nt)) {
#pragma omp single
      fits = false;
    } else {
      const long jlo = n1 * t / nt, jhi = n1 * (t + 1) / nt, nj = jhi - jlo;
      const long m1 = nj + 2 * GHOST, plane = m1 * m2, slots = RING + 2;
      T* ring = ring_all + t * per;
      const Consts<T>& k = kg;  // the ring's rows have the padded row stride (planes are reached through the tables)
      RowBuffers<T> r(nj, n2);  // nj >= MIN_ROWS: fused_threads
      std::vector<T*> out(NRING);  // the program's outputs: the ring's fields
      // Slot of plane p (-2 <= p < n0 + 2; planes 0, 1 and their periodic images n0, n0 + 1 in the kept slots).
      auto slot_of = [&](long p) {
        const long q = p >= n0 ? p - n0 : p;
        return q == 0 || q == 1 ? RING + q : ((q % RING) + RING) % RING;
      };
      auto field = [&](int f, long s) { return ring + (long(f) * slots + s) * plane; };
      // The cell program on the thread's rows (and ghost rows) of plane p of Uk (p < n0), into its slot.
      auto place = [&](long p) {
        if (p >= n0) return;  // planes 0, 1 again: kept
        const long gp = (p + n0) % n0, s = slot_of(p);
        for (long jj = 0; jj < m1; ++jj) {
          const long J = jlo - GHOST + jj;
          if (gaxis == 1 && (J < 0 || J >= n1)) {  // a ghost row of a boundary along y: the caller's (set_ghosts)
            const long side = J < 0 ? 0 : 1, q = J < 0 ? J + GHOST : J - n1;
            for (int f = 0; f < NFIELD; ++f) {
              const T* src = ghost + (((long(f) * 2 + side) * GHOST + q) * (n0 + 2 * GHOST) + gp + GHOST) * m2;
              std::copy(src, src + m2, field(f, s) + jj * m2);
            }
            continue;
          }
          const long gj = (J % n1 + n1) % n1, at = (gp * n1 + gj) * n2;
          const T* in[5];
          for (int v = 0; v < 5; ++v) in[v] = o.Uk[v] + at;
          for (int f = 0; f < NRING; ++f) out[f] = field(f, s) + jj * m2 + GHOST;
          fn(n2, leaf, in, out.data());
          for (int f = 0; f < NFIELD; ++f) {  // the row's ghost cells along z: periodic, or the caller's
            T* row = out[f] - GHOST;
            const long m1g = n1 + 2 * GHOST;
            for (long q = 0; q < GHOST; ++q) {
              if (gaxis == 2) {
                row[q] = ghost[((long(f) * 2 * GHOST + q) * (n0 + 2 * GHOST) + gp + GHOST) * m1g + gj + GHOST];
                row[GHOST + n2 + q] =
                    ghost[((long(f) * 2 * GHOST + GHOST + q) * (n0 + 2 * GHOST) + gp + GHOST) * m1g + gj + GHOST];
              } else {
                row[q] = row[n2 + q];
                row[GHOST + n2 + q] = row[GHOST + q];
              }
            }
          }
        }
        progress[t].placed.store(p, std::memory_order_release);
      };
      auto table = [&](long p, const T** tab) {  // the fields of planes p - 1, p, p + 1
        for (int d = 0; d < 3; ++d)
          for (int f = 0; f < NFIELD; ++f) tab[d * NFIELD + f] = field(f, slot_of(p - 1 + d));
      };
      auto row = [&](long b) { return (b + GHOST) * m2 + GHOST; };
      const T* P0[3 * NFIELD];
      const T* P1[3 * NFIELD];
      for (long p = -2; p < 2; ++p) place(p);
      table(-1, P0);
      table(0, P1);
      start_block<T, LIM, RIE, true>(P0, P1, nj, row, k, r);
      for (long i = 0; i < n0; ++i) {
        place(i + 2);
        table(i, P0);
        table(i + 1, P1);
        const long si = slot_of(i), out0 = (i * n1 + jlo) * n2;
        if (shared) wait_for(progress.data(), t, nt, i);  // before U' of plane i overwrites their ghost rows' Uk
        sweep_rows<T, LIM, RIE, true>(P0, P1, nj, row, [&](long b) { return out0 + b * n2; },
                                      [&](long b, const T** src) {
                                        src[0] = field(NFIELD, si) + row(b);
                                        src[1] = field(NFIELD + 1, si) + row(b);
                                      }, k, o, r);
      }
    }
  }
  return fits;
}

constexpr size_t NSTAGE_PARAMS = 9;

// A stage's output (Stage) with params (dx, dy, dz, rho_s, a, dt, g_x, g_y, g_z), U0 and Uk the fields from in[u0],
// in[uk]; with a ghost axis, its boundary corrections (Stage::fix) from in[fix], checked against the grid n.
ffi::Error stage_output(const double* p, ffi::RemainingArgs in, size_t u0, size_t uk, int axis, size_t fix,
                        const long* n, std::array<ffi::Result<ffi::AnyBuffer>, 5> out, Stage<Real>& o) {
  for (int v = 0; v < 5; ++v) {
    o.U0[v] = in.get<ffi::AnyBuffer>(u0 + v)->typed_data<Real>();
    o.Uk[v] = in.get<ffi::AnyBuffer>(uk + v)->typed_data<Real>();
    o.U[v] = out[v]->typed_data<Real>();
  }
  o.s0 = o.s1 = nullptr;
  o.a = Real(p[4]);
  o.b = Real(1) - o.a;  // as the JAX path: 1 - a in the state precision
  o.dt = Real(p[5]);
  for (int a = 0; a < 3; ++a) o.g[a] = Real(p[6 + a]);
  o.gravity = p[6] != 0 || p[7] != 0 || p[8] != 0;
  o.fix = nullptr;
  o.fix_axis = axis;
  if (axis < 0) return ffi::Error::Success();
  auto f = in.get<ffi::AnyBuffer>(fix);
  const long np = axis == 0 ? n[1] * n[2] : axis == 1 ? n[0] * n[2] : n[0] * n[1];
  if (!f.has_value() || long(f->element_count()) != 10 * np || f->element_type() != in.get<ffi::AnyBuffer>(0)->element_type())
    return ffi::Error::InvalidArgument("stage kernel: boundary corrections = 2 ends x 5 fields x the cells of a plane "
                                       "across the ghost axis, in the fields' precision");
  o.fix = f->typed_data<Real>();
  return ffi::Error::Success();
}

ffi::Error ssprk_stage(ffi::Buffer<ffi::F64> params, ffi::RemainingArgs in, int32_t limiter, int32_t riemann,
                       ffi::Result<ffi::AnyBuffer> u0, ffi::Result<ffi::AnyBuffer> u1, ffi::Result<ffi::AnyBuffer> u2,
                       ffi::Result<ffi::AnyBuffer> u3, ffi::Result<ffi::AnyBuffer> u4,
                       ffi::Result<ffi::AnyBuffer> work) {
  const size_t nin = NFIELD + 12;
  const bool bounded = in.size() == nin + 2;
  if (params.element_count() != NSTAGE_PARAMS + bounded)
    return ffi::Error::InvalidArgument("stage kernel: params = (dx, dy, dz, rho_s, a, dt, g_x, g_y, g_z[, ghost axis])");
  if (in.size() != nin + 2 * bounded)
    return ffi::Error::InvalidArgument("stage kernel: fields = (the 11 cell fields, U0 x5, Uk x5, s0, s1[, ghost "
                                       "planes, boundary corrections])");
  ffi::DataType type, state_type;
  if (auto err = same_fields(in, NFIELD, type); err.failure()) return err;
  if (auto err = same_fields(in, 12, state_type, NFIELD); err.failure()) return err;
  if (state_type != type) return ffi::Error::InvalidArgument("stage kernel: the fields must be of one precision");
  if (auto err = check_variant("KtgfSsprkStage", type, limiter, riemann, true); err.failure()) return err;
  const double* p = params.typed_data();
  long n[3];
  if (auto err = grid_shape(*in.get<ffi::AnyBuffer>(NFIELD), n); err.failure()) return err;
  Stage<Real> o;
  if (auto err = stage_output(p, in, NFIELD, NFIELD + 5, bounded ? int(p[NSTAGE_PARAMS]) : -1, nin + 1, n,
                              {u0, u1, u2, u3, u4}, o);
      err.failure())
    return err;
  o.s0 = in.get<ffi::AnyBuffer>(NFIELD + 10)->typed_data<Real>();
  o.s1 = in.get<ffi::AnyBuffer>(NFIELD + 11)->typed_data<Real>();
  return run(in, nin, *in.get<ffi::AnyBuffer>(NFIELD), p, NSTAGE_PARAMS, work->typed_data<Real>(), o);
}

// The cell program registered under `program`, checked against the precision of `type`.
ffi::Error find_program(int64_t program, ffi::DataType type, CellProgram& p) {
  {
    std::lock_guard<std::mutex> lock(programs_mutex);
    auto it = programs.find(program);
    if (it != programs.end()) p = it->second;
  }
  const int bits = type == ffi::F64 ? 64 : type == ffi::F32 ? 32 : 0;
  if (p.fn == nullptr) return ffi::Error::InvalidArgument("stage kernel: cell program not registered");
  if (p.bits != bits) return ffi::Error::InvalidArgument("stage kernel: cell program of another precision");
  return ffi::Error::Success();
}

// KtgfCellLimits: the maxima of the terms (as many as `maxima` holds) of a step-start cell program at Uk
// (cell_limits).  It does not depend on the limiter or the Riemann solver of its library.
ffi::Error cell_limits_entry(ffi::Buffer<ffi::F64> leaf, ffi::RemainingArgs state, int64_t program,
                             ffi::Result<ffi::AnyBuffer> maxima) {
  if (state.size() != 5) return ffi::Error::InvalidArgument("cell limits kernel: state = Uk x5");
  ffi::DataType type;
  if (auto err = same_fields(state, 5, type); err.failure()) return err;
  if (auto err = check_variant("KtgfCellLimits", type, KTGF_LIMITER, KTGF_RIEMANN, true); err.failure()) return err;
  if (maxima->element_type() != type)
    return ffi::Error::InvalidArgument("cell limits kernel: maxima must be of the state precision");
  const int nlim = int(maxima->element_count());
  CellProgram p{nullptr, 0};
  if (auto err = find_program(program, type, p); err.failure()) return err;
  long n[3];
  if (auto err = grid_shape(*state.get<ffi::AnyBuffer>(0), n); err.failure()) return err;
  const Real* U[5];
  for (int v = 0; v < 5; ++v) U[v] = state.get<ffi::AnyBuffer>(v)->typed_data<Real>();
  cell_limits<Real>(reinterpret_cast<CellsFn<Real>>(p.fn), leaf.typed_data(), U, n, nlim, maxima->typed_data<Real>());
  return ffi::Error::Success();
}

// KtgfSsprkStageCells (sweep_fused; `ring` its per-thread planes, ring_elements): state (U0, Uk[, ghost planes,
// boundary corrections]).
ffi::Error ssprk_stage_cells(ffi::Buffer<ffi::F64> params, ffi::Buffer<ffi::F64> leaf, ffi::RemainingArgs state,
                             int32_t limiter, int32_t riemann, int64_t program, ffi::Result<ffi::AnyBuffer> u0,
                             ffi::Result<ffi::AnyBuffer> u1, ffi::Result<ffi::AnyBuffer> u2,
                             ffi::Result<ffi::AnyBuffer> u3, ffi::Result<ffi::AnyBuffer> u4,
                             ffi::Result<ffi::AnyBuffer> ring) {
  const size_t nstate = 10;
  const bool bounded = state.size() == nstate + 2;
  if (params.element_count() != NSTAGE_PARAMS + bounded)
    return ffi::Error::InvalidArgument("stage kernel: params = (dx, dy, dz, rho_s, a, dt, g_x, g_y, g_z[, ghost axis])");
  if (state.size() != nstate + 2 * bounded)
    return ffi::Error::InvalidArgument("stage kernel: state = (U0 x5, Uk x5[, ghost planes, boundary corrections])");
  ffi::DataType type;
  if (auto err = same_fields(state, nstate, type); err.failure()) return err;
  if (auto err = check_variant("KtgfSsprkStageCells", type, limiter, riemann, true); err.failure()) return err;
  CellProgram p{nullptr, 0};
  if (auto err = find_program(program, type, p); err.failure()) return err;
  long n[3];
  if (auto err = grid_shape(*state.get<ffi::AnyBuffer>(0), n); err.failure()) return err;
  if (ring->element_type() != type || long(ring->element_count()) < ring_elements(n))
    return ffi::Error::InvalidArgument("stage kernel: the ring workspace is smaller than KtgfRingElements");
  const double* par = params.typed_data();
  const Real* ghost;
  int axis;
  if (auto err = ghost_planes(state, nstate, par, NSTAGE_PARAMS, NFIELD, n, ghost, axis); err.failure()) return err;
  if (axis == 0) return ffi::Error::InvalidArgument("stage kernel: cell programs take ghost planes along y or z only");
  Stage<Real> o;  // s0, s1: the ring's
  if (auto err = stage_output(par, state, 0, 5, axis, nstate + 1, n, {u0, u1, u2, u3, u4}, o); err.failure()) return err;
  Consts<Real> k = consts(n, par);
  k.wrap2 = axis != 2;
  if (!sweep_fused<Real, KTGF_LIMITER, KTGF_RIEMANN>(reinterpret_cast<CellsFn<Real>>(p.fn), leaf.typed_data(), k, o,
                                                     ring->typed_data<Real>(), long(ring->element_count()), ghost,
                                                     axis))
    return ffi::Error::InvalidArgument("stage kernel: the ring workspace is too small for the threads");
  return ffi::Error::Success();
}
#endif  // KTGF_KIND

}  // namespace

#if KTGF_KIND != KTGF_STAGE
XLA_FFI_DEFINE_HANDLER_SYMBOL(KtgfFluxDivergence, flux_divergence,
                              ffi::Ffi::Bind()
                                  .Arg<ffi::Buffer<ffi::F64>>()  // (dx, dy, dz, rho_s)
                                  .RemainingArgs()               // the cell fields (enum Field)
                                  .Attr<int32_t>("limiter")
                                  .Attr<int32_t>("riemann")
                                  .Attr<int32_t>("viscous")
                                  .Ret<ffi::AnyBuffer>()  // -div F of rho
                                  .Ret<ffi::AnyBuffer>()  // ... rho u_x
                                  .Ret<ffi::AnyBuffer>()  // ... rho u_y
                                  .Ret<ffi::AnyBuffer>()  // ... rho u_z
                                  .Ret<ffi::AnyBuffer>()  // ... E
                                  .Ret<ffi::AnyBuffer>()  // div u
                                  .Ret<ffi::AnyBuffer>());  // padded fields (workspace)

#else  // the stage kind
XLA_FFI_DEFINE_HANDLER_SYMBOL(KtgfSsprkStage, ssprk_stage,
                              ffi::Ffi::Bind()
                                  .Arg<ffi::Buffer<ffi::F64>>()  // (dx, dy, dz, rho_s, a, dt, g)
                                  .RemainingArgs()               // cell fields at Uk, U0, Uk (5 each), s0, s1[, ghosts, fix]
                                  .Attr<int32_t>("limiter")
                                  .Attr<int32_t>("riemann")
                                  .Ret<ffi::AnyBuffer>()  // U' density
                                  .Ret<ffi::AnyBuffer>()  // ... rho u_x
                                  .Ret<ffi::AnyBuffer>()  // ... rho u_y
                                  .Ret<ffi::AnyBuffer>()  // ... rho u_z
                                  .Ret<ffi::AnyBuffer>()  // ... E
                                  .Ret<ffi::AnyBuffer>());  // padded fields (workspace)

XLA_FFI_DEFINE_HANDLER_SYMBOL(KtgfSsprkStageCells, ssprk_stage_cells,
                              ffi::Ffi::Bind()
                                  .Arg<ffi::Buffer<ffi::F64>>()  // (dx, dy, dz, rho_s, a, dt, g)
                                  .Arg<ffi::Buffer<ffi::F64>>()  // the cell program's parameters
                                  .RemainingArgs()               // U0 (5), Uk (5)[, ghost planes, boundary fix]
                                  .Attr<int32_t>("limiter")
                                  .Attr<int32_t>("riemann")
                                  .Attr<int64_t>("program")
                                  .Ret<ffi::AnyBuffer>()  // U' density
                                  .Ret<ffi::AnyBuffer>()  // ... rho u_x
                                  .Ret<ffi::AnyBuffer>()  // ... rho u_y
                                  .Ret<ffi::AnyBuffer>()  // ... rho u_z
                                  .Ret<ffi::AnyBuffer>()  // ... E
                                  .Ret<ffi::AnyBuffer>());  // the planes of the fused sweep (workspace, KtgfRingElements)

XLA_FFI_DEFINE_HANDLER_SYMBOL(KtgfCellLimits, cell_limits_entry,
                              ffi::Ffi::Bind()
                                  .Arg<ffi::Buffer<ffi::F64>>()  // the cell program's parameters
                                  .RemainingArgs()               // Uk (5)
                                  .Attr<int64_t>("program")
                                  .Ret<ffi::AnyBuffer>());  // maxima of the program's limit terms

// Registers the cell program `fn` (state precision `bits`, 32 or 64) under `key` in this library; returns 0, or
// 1 (nothing registered) if this library is built for the other precision.
extern "C" int KtgfRegisterCells(int64_t key, void* fn, int32_t bits) {
  if (bits != 8 * int(sizeof(Real))) return 1;
  std::lock_guard<std::mutex> lock(programs_mutex);
  programs[key] = CellProgram{fn, bits};
  return 0;
}

// Elements of the workspace (ring) KtgfSsprkStageCells needs on an (n0, n1, n2) grid with this process's threads.
extern "C" long KtgfRingElements(long n0, long n1, long n2) {
  const long n[3] = {n0, n1, n2};
  return ring_elements(n);
}
#endif  // KTGF_KIND
