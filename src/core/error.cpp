#include "core/error.hpp"

namespace clumpforge {

std::string_view to_string(ErrorCode code) {
  switch (code) {
    case ErrorCode::InvalidArgument: return "invalid argument";
    case ErrorCode::NotFound: return "not found";
    case ErrorCode::ParseError: return "parse error";
    case ErrorCode::InvalidMesh: return "invalid mesh";
    case ErrorCode::RepairFailed: return "repair failed";
    case ErrorCode::IoError: return "i/o error";
    case ErrorCode::Cancelled: return "cancelled";
  }
  return "unknown error";
}

}  // namespace clumpforge
