// SDFCage — Core: see VectorMath.h. This translation unit alone is compiled with -ffast-math
// -fopenmp-simd (Core/CMakeLists.txt) so that the loops below call libmvec's vector functions;
// nothing else lives here, so the fast-math assumptions (finite inputs, no errno) hold.
#include "Deformation/VectorMath.h"

#include <cmath>

namespace sdfcage
{

void vectorLog(const double* in, double* out, int n)
{
#pragma omp simd
  for (int i = 0; i < n; ++i)
  {
    out[i] = std::log(in[i]);
  }
}

void vectorAtan(const double* in, double* out, int n)
{
#pragma omp simd
  for (int i = 0; i < n; ++i)
  {
    out[i] = std::atan(in[i]);
  }
}

void floatRowTimes3(const float* w, const double* bx, const double* by, const double* bz, int n, double out[3])
{
  double sx = 0.0, sy = 0.0, sz = 0.0;
#pragma omp simd reduction(+ : sx, sy, sz)
  for (int i = 0; i < n; ++i)
  {
    const double wi = static_cast<double>(w[i]);
    sx += wi * bx[i];
    sy += wi * by[i];
    sz += wi * bz[i];
  }
  out[0] = sx;
  out[1] = sy;
  out[2] = sz;
}

void rowTimes3(const double* w, const double* bx, const double* by, const double* bz, int n, double out[3])
{
  double sx = 0.0, sy = 0.0, sz = 0.0;
#pragma omp simd reduction(+ : sx, sy, sz)
  for (int i = 0; i < n; ++i)
  {
    sx += w[i] * bx[i];
    sy += w[i] * by[i];
    sz += w[i] * bz[i];
  }
  out[0] = sx;
  out[1] = sy;
  out[2] = sz;
}

} // namespace sdfcage
