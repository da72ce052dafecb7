#include "Common/Status.h"

namespace sdfcage
{

const char* statusName(Status s)
{
  switch (s)
  {
    case Status::Ok:
      return "ok";
    case Status::EmptyInput:
      return "empty input";
    case Status::InvalidInput:
      return "invalid input";
    case Status::Cancelled:
      return "cancelled";
    case Status::VerificationFailed:
      return "verification failed";
    case Status::Failed:
      return "failed";
    case Status::TopologyChanged:
      return "topology changed";
  }
  return "unknown";
}

} // namespace sdfcage
