#pragma once
/// Part of the installed interface (<clumpforge/error.hpp>): the standard library only.
/// Errors and results: every expected failure is an `Error` inside a `Result`.
#include <expected>
#include <string>
#include <string_view>

namespace clumpforge {

/// What kind of failure; the CLI maps these to exit codes (see README.md).
enum class ErrorCode {
  InvalidArgument,  ///< an option is out of range or malformed
  NotFound,         ///< a file or directory does not exist
  ParseError,       ///< a file's content could not be read as its format
  InvalidMesh,      ///< the geometry breaks a precondition (open, inside-out, ...)
  RepairFailed,     ///< a repair step could not reach its goal
  IoError,          ///< writing or reading failed at the operating-system level
  Cancelled,        ///< the run context asked to stop
};

struct Error {
  ErrorCode code = ErrorCode::InvalidArgument;
  std::string message;  ///< names the input and what is wrong with it
};

template <class T>
using Result = std::expected<T, Error>;

/// Shorthand for returning a failure: `return fail(ErrorCode::NotFound, "...")`.
inline std::unexpected<Error> fail(ErrorCode code, std::string message) {
  return std::unexpected<Error>(Error{code, std::move(message)});
}

std::string_view to_string(ErrorCode code);

/// A finding that is not fatal, carried in a result's `notes`.
struct Diagnostic {
  enum class Severity { Info, Warning };
  Severity severity = Severity::Info;
  std::string message;
};

}  // namespace clumpforge
