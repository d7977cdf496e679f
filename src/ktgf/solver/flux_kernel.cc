// CPU fast path of ktgf.solver.fluxes.flux_divergence on a fully periodic 3D grid (numerics only).
//
// Same formulas, in the same operation order, as the JAX functions of fluxes.py (reconstruct,
// riemann_flux, stress, heat_flux, stress_work, face_divergence, cell_divergence): the JAX path
// is the reference, this kernel is checked against it to round-off (tests/test_solver_flux_kernel.py).
// Why a kernel: XLA recomputes every face state and wave speed inside each of the five flux
// components of an axis (docs/solver.md, Speed); here each face is computed once, from cells
// that sit in cache, and its flux goes to the two cells it separates.
//
// Inputs: the cell fields (rho, u_x, u_y, u_z, theta, p*, g, eta, lambda_b, kappa, omega), each
// of shape (n0, n1, n2), C order, and float64 (dx, dy, dz, material density).  Outputs: -div F of
// the five conservative fields, the central div u, and a workspace holding the fields with two
// periodic ghost cells per side (an output so that XLA owns and reuses its memory).
#include <cmath>
#include <cstdint>
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
  long stride[3];
  T inv_dx[3];        // 1/dx_a (normal derivatives)
  T half_inv_dx[3];   // 0.5/dx_a (central derivatives)
  T dx[3];            // face divergence divides by dx_a
  T omega_factor[3];  // (1/dx_a)/rho_s
};

// Flux through the face between padded cells c and c + stride[A] along axis A: out[v * ld].
template <class T, int A, int LIM, int RIE, bool VISC>
KTGF_INLINE void face_flux(const T* const* P, long c, const Consts<T>& k, T* out, long ld) {
  const long sa = k.stride[A];
  T WL[7], WR[7];
  for (int f = 0; f < 7; ++f) {  // fluxes.reconstruct: MUSCL left/right states
    const T* p = P[f];
    const T fm = p[c - sa], f0 = p[c], f1 = p[c + sa], f2 = p[c + 2 * sa];
    WL[f] = f0 + T(0.5) * slope<T, LIM>(f0 - fm, f1 - f0);
    WR[f] = f1 - T(0.5) * slope<T, LIM>(f1 - f0, f2 - f1);
  }
  // fluxes.riemann_flux
  const T pL = WL[RHO] * WL[TH] * WL[PS], pR = WR[RHO] * WR[TH] * WR[PS];
  const T cL = std::sqrt(WL[TH] * WL[GG]), cR = std::sqrt(WR[TH] * WR[GG]);
  const T uL = WL[1 + A], uR = WR[1 + A];
  T UL[5], UR[5], FL[5], FR[5];
  UL[0] = WL[RHO];
  UR[0] = WR[RHO];
  for (int j = 0; j < 3; ++j) {
    UL[1 + j] = WL[RHO] * WL[1 + j];
    UR[1 + j] = WR[RHO] * WR[1 + j];
  }
  const T keL = T(0.5) * (WL[UX] * WL[UX] + WL[UY] * WL[UY] + WL[UZ] * WL[UZ]);
  const T keR = T(0.5) * (WR[UX] * WR[UX] + WR[UY] * WR[UY] + WR[UZ] * WR[UZ]);
  UL[4] = WL[RHO] * (keL + T(1.5) * WL[TH]);
  UR[4] = WR[RHO] * (keR + T(1.5) * WR[TH]);
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
    for (int v = 0; v < 5; ++v) F[v] = T(0.5) * (FL[v] + FR[v]) - T(0.5) * smax * (UR[v] - UL[v]);
  } else {  // HLL, Davis wave speeds
    const T sl = min2(min2(uL - cL, uR - cR), T(0));
    const T sr = max2(max2(uL + cL, uR + cR), T(0));
    const T inv = T(1) / (sr - sl);
    for (int v = 0; v < 5; ++v) F[v] = (sr * FL[v] - sl * FR[v] + sl * sr * (UR[v] - UL[v])) * inv;
  }
  if (VISC) {  // fluxes.viscous_flux: central stress and heat flux, face coefficients = cell means
    const T eta = T(0.5) * (P[ETA][c] + P[ETA][c + sa]);
    const T lam = T(0.5) * (P[LAM][c] + P[LAM][c + sa]);
    const T kap = T(0.5) * (P[KAP][c] + P[KAP][c + sa]);
    const T omg = T(0.5) * (P[OMG][c] + P[OMG][c + sa]);
    T grad[3][3];  // grad[b][j] = d u_j / d x_b at the face
    for (int b = 0; b < 3; ++b) {
      for (int j = 0; j < 3; ++j) {
        const T* u = P[UX + j];
        if (b == A) {
          grad[b][j] = (u[c + sa] - u[c]) * k.inv_dx[A];
        } else {
          const long sb = k.stride[b];
          const T g0 = (u[c + sb] - u[c - sb]) * k.half_inv_dx[b];
          const T g1 = (u[c + sa + sb] - u[c + sa - sb]) * k.half_inv_dx[b];
          grad[b][j] = T(0.5) * (g0 + g1);
        }
      }
    }
    const T divu = grad[0][0] + grad[1][1] + grad[2][2];
    T tau[3];
    for (int j = 0; j < 3; ++j) tau[j] = eta * (grad[A][j] + grad[j][A]);
    tau[A] = tau[A] + (lam - T(2.0 / 3.0) * eta) * divu;
    const T q = -kap * (P[TH][c + sa] - P[TH][c]) * k.inv_dx[A] -
                omg * (P[RHO][c + sa] - P[RHO][c]) * k.omega_factor[A];
    T work = T(0);
    for (int j = 0; j < 3; ++j) work = work + tau[j] * (T(0.5) * (P[UX + j][c] + P[UX + j][c + sa]));
    F[1] = F[1] + -tau[0];
    F[2] = F[2] + -tau[1];
    F[3] = F[3] + -tau[2];
    F[4] = F[4] + (q - work);
  }
  for (int v = 0; v < 5; ++v) out[v * ld] = F[v];
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

// -div F and div u.  Each thread owns a block of planes i and sweeps its rows (i, j) in order,
// keeping the fluxes of the lower x faces (a plane) and y faces (a row) from the previous
// plane/row, so every face is computed once (plus one x plane per thread).
template <class T, int LIM, int RIE, bool VISC>
void divergence(const T* const* P, const long* n, const Consts<T>& k, T* const* dU, T* divu) {
  const long n0 = n[0], n1 = n[1], n2 = n[2];
  const long s0 = k.stride[0], s1 = k.stride[1];
  auto cell = [&](long i, long j, long q) { return (i + GHOST) * s0 + (j + GHOST) * s1 + q + GHOST; };
#pragma omp parallel
  {
    std::vector<T> xlo(5 * n1 * n2), xhi(5 * n2), ylo(5 * n2), yhi(5 * n2), zf(5 * (n2 + 1));
    int nt = 1, t = 0;
#ifdef _OPENMP
    nt = omp_get_num_threads();
    t = omp_get_thread_num();
#endif
    const long i0 = n0 * t / nt, i1 = n0 * (t + 1) / nt;
    if (i0 < i1) {
      for (long j = 0; j < n1; ++j) {
        T* dst = xlo.data() + j * n2;
#pragma omp simd
        for (long q = 0; q < n2; ++q) face_flux<T, 0, LIM, RIE, VISC>(P, cell(i0 - 1, j, q), k, dst + q, n1 * n2);
      }
    }
    for (long i = i0; i < i1; ++i) {
#pragma omp simd
      for (long q = 0; q < n2; ++q) face_flux<T, 1, LIM, RIE, VISC>(P, cell(i, -1, q), k, ylo.data() + q, n2);
      for (long j = 0; j < n1; ++j) {
        const long c0 = cell(i, j, 0);
#pragma omp simd
        for (long q = 0; q < n2; ++q) face_flux<T, 0, LIM, RIE, VISC>(P, c0 + q, k, xhi.data() + q, n2);
#pragma omp simd
        for (long q = 0; q < n2; ++q) face_flux<T, 1, LIM, RIE, VISC>(P, c0 + q, k, yhi.data() + q, n2);
#pragma omp simd
        for (long q = 0; q <= n2; ++q) face_flux<T, 2, LIM, RIE, VISC>(P, c0 + q - 1, k, zf.data() + q, n2 + 1);
        const long out = (i * n1 + j) * n2;
        for (int v = 0; v < 5; ++v) {
          T* xl = xlo.data() + v * n1 * n2 + j * n2;
          const T* xh = xhi.data() + v * n2;
          T* yl = ylo.data() + v * n2;
          const T* yh = yhi.data() + v * n2;
          const T* z = zf.data() + v * (n2 + 1);
          T* o = dU[v] + out;
#pragma omp simd
          for (long q = 0; q < n2; ++q) {
            T d = (xl[q] - xh[q]) / k.dx[0];
            d = d + (yl[q] - yh[q]) / k.dx[1];
            o[q] = d + (z[q] - z[q + 1]) / k.dx[2];
            xl[q] = xh[q];
            yl[q] = yh[q];
          }
        }
        const T* ux = P[UX] + c0;
        const T* uy = P[UY] + c0;
        const T* uz = P[UZ] + c0;
        T* dv = divu + out;
#pragma omp simd
        for (long q = 0; q < n2; ++q) {
          dv[q] = (ux[q + s0] - ux[q - s0]) * k.half_inv_dx[0] + (uy[q + s1] - uy[q - s1]) * k.half_inv_dx[1] +
                  (uz[q + 1] - uz[q - 1]) * k.half_inv_dx[2];
        }
      }
    }
  }
}

template <class T, int LIM, int RIE>
void dispatch_visc(bool viscous, const T* const* P, const long* n, const Consts<T>& k, T* const* dU, T* divu) {
  if (viscous) divergence<T, LIM, RIE, true>(P, n, k, dU, divu);
  else divergence<T, LIM, RIE, false>(P, n, k, dU, divu);
}

template <class T, int LIM>
void dispatch_riemann(int riemann, bool viscous, const T* const* P, const long* n, const Consts<T>& k, T* const* dU,
                      T* divu) {
  if (riemann == RUSANOV) dispatch_visc<T, LIM, RUSANOV>(viscous, P, n, k, dU, divu);
  else dispatch_visc<T, LIM, HLL>(viscous, P, n, k, dU, divu);
}

template <class T>
ffi::Error run(const std::vector<ffi::AnyBuffer>& in, double rho_s, const double* dx, int limiter, int riemann,
               bool viscous, const std::vector<void*>& out) {
  auto dims = in[0].dimensions();
  if (dims.size() != 3) return ffi::Error::InvalidArgument("flux kernel: fields must be 3D");
  const long n[3] = {long(dims[0]), long(dims[1]), long(dims[2])};
  if (n[0] < GHOST || n[1] < GHOST || n[2] < GHOST)
    return ffi::Error::InvalidArgument("flux kernel: at least 2 cells per axis");
  const int nfield = viscous ? NFIELD : GG + 1;
  std::vector<const T*> fields(NFIELD, nullptr);
  for (int f = 0; f < nfield; ++f) fields[f] = in[f].typed_data<T>();
  T* work = static_cast<T*>(out[6]);
  pad<T>(fields.data(), nfield, n, work);
  const long m[3] = {n[0] + 2 * GHOST, n[1] + 2 * GHOST, n[2] + 2 * GHOST};
  std::vector<const T*> P(NFIELD, nullptr);
  for (int f = 0; f < nfield; ++f) P[f] = work + f * m[0] * m[1] * m[2];
  Consts<T> k;
  k.stride[0] = m[1] * m[2];
  k.stride[1] = m[2];
  k.stride[2] = 1;
  for (int a = 0; a < 3; ++a) {
    k.inv_dx[a] = T(1.0 / dx[a]);
    k.half_inv_dx[a] = T(0.5 / dx[a]);
    k.dx[a] = T(dx[a]);
    k.omega_factor[a] = T((1.0 / dx[a]) / rho_s);
  }
  T* dU[5];
  for (int v = 0; v < 5; ++v) dU[v] = static_cast<T*>(out[v]);
  T* divu = static_cast<T*>(out[5]);
  switch (limiter) {
    case MINMOD: dispatch_riemann<T, MINMOD>(riemann, viscous, P.data(), n, k, dU, divu); break;
    case VANLEER: dispatch_riemann<T, VANLEER>(riemann, viscous, P.data(), n, k, dU, divu); break;
    case MC: dispatch_riemann<T, MC>(riemann, viscous, P.data(), n, k, dU, divu); break;
    case NONE: dispatch_riemann<T, NONE>(riemann, viscous, P.data(), n, k, dU, divu); break;
    default: return ffi::Error::InvalidArgument("flux kernel: unknown limiter");
  }
  return ffi::Error::Success();
}

ffi::Error flux_divergence(ffi::AnyBuffer rho, ffi::AnyBuffer ux, ffi::AnyBuffer uy, ffi::AnyBuffer uz,
                           ffi::AnyBuffer theta, ffi::AnyBuffer pstar, ffi::AnyBuffer g, ffi::AnyBuffer eta,
                           ffi::AnyBuffer lam, ffi::AnyBuffer kap, ffi::AnyBuffer omega,
                           ffi::Buffer<ffi::F64> params, int32_t limiter,
                           int32_t riemann, int32_t viscous, ffi::Result<ffi::AnyBuffer> d0,
                           ffi::Result<ffi::AnyBuffer> d1, ffi::Result<ffi::AnyBuffer> d2,
                           ffi::Result<ffi::AnyBuffer> d3, ffi::Result<ffi::AnyBuffer> d4,
                           ffi::Result<ffi::AnyBuffer> divu, ffi::Result<ffi::AnyBuffer> work) {
  const std::vector<ffi::AnyBuffer> in = {rho, ux, uy, uz, theta, pstar, g, eta, lam, kap, omega};
  const std::vector<void*> out = {d0->untyped_data(), d1->untyped_data(), d2->untyped_data(), d3->untyped_data(),
                                 d4->untyped_data(), divu->untyped_data(), work->untyped_data()};
  if (params.element_count() != 4) return ffi::Error::InvalidArgument("flux kernel: params = (dx, dy, dz, rho_s)");
  const double* spacing = params.typed_data();
  const double rs = spacing[3];
  switch (rho.element_type()) {
    case ffi::F64: return run<double>(in, rs, spacing, limiter, riemann, viscous != 0, out);
    case ffi::F32: return run<float>(in, rs, spacing, limiter, riemann, viscous != 0, out);
    default: return ffi::Error::InvalidArgument("flux kernel: fields must be float32 or float64");
  }
}

}  // namespace

XLA_FFI_DEFINE_HANDLER_SYMBOL(KtgfFluxDivergence, flux_divergence,
                              ffi::Ffi::Bind()
                                  .Arg<ffi::AnyBuffer>()  // rho
                                  .Arg<ffi::AnyBuffer>()  // u_x
                                  .Arg<ffi::AnyBuffer>()  // u_y
                                  .Arg<ffi::AnyBuffer>()  // u_z
                                  .Arg<ffi::AnyBuffer>()  // theta
                                  .Arg<ffi::AnyBuffer>()  // p*
                                  .Arg<ffi::AnyBuffer>()  // g
                                  .Arg<ffi::AnyBuffer>()  // eta
                                  .Arg<ffi::AnyBuffer>()  // lambda_b
                                  .Arg<ffi::AnyBuffer>()  // kappa
                                  .Arg<ffi::AnyBuffer>()  // omega
                                  .Arg<ffi::Buffer<ffi::F64>>()  // (dx, dy, dz, rho_s)
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
