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

} // namespace sdfcage
