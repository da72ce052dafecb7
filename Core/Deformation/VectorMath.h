// SDFCage — Core: the logarithm and arctangent of whole arrays, for the cage coordinates' inner
// loops. VectorMath.cxx is compiled so that GCC calls glibc's vector math library (libmvec, 2
// lanes with SSE2; at most 4 ulp, against 1 for the scalar functions): about twice as fast as a
// loop of std::log / std::atan here. Other compilers get the plain loops (same results to 4 ulp).
#pragma once

namespace sdfcage
{
/// out[i] = log(in[i]) for in[i] > 0 (finite).
void vectorLog(const double* in, double* out, int n);
/// out[i] = atan(in[i]) for finite in[i].
void vectorAtan(const double* in, double* out, int n);
/// out = (w . bx, w . by, w . bz) for single-precision w, accumulated in double precision (in an
/// order the compiler chooses: vectorized).
void floatRowTimes3(const float* w, const double* bx, const double* by, const double* bz, int n, double out[3]);
/// The same for a double-precision w.
void rowTimes3(const double* w, const double* bx, const double* by, const double* bz, int n, double out[3]);
} // namespace sdfcage
