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

/// `text` safe to print and to pass on as UTF-8: each byte of an invalid UTF-8 sequence, and
/// each control character but a newline or a tab, written as \xNN. An error message quotes
/// what it read from a file (a damaged number, a name), and a file may hold anything: raw bytes
/// broke the Python module's exception (a UnicodeDecodeError instead of ParseError) and an
/// escape sequence would reach the user's terminal.
std::string printable_text(std::string_view text);

/// Whether `text` is valid UTF-8 throughout. A name that goes into a JSON record (a scan's file
/// name, a trial's id) must be: a Linux file name may hold any byte, and JSON text cannot.
bool is_valid_utf8(std::string_view text);

/// Shorthand for returning a failure: `return fail(ErrorCode::NotFound, "...")`. The message is
/// made printable (printable_text).
inline std::unexpected<Error> fail(ErrorCode code, std::string_view message) {
  return std::unexpected<Error>(Error{code, printable_text(message)});
}

std::string_view to_string(ErrorCode code);

/// A finding that is not fatal, carried in a result's `notes`.
struct Diagnostic {
  enum class Severity { Info, Warning };
  Severity severity = Severity::Info;
  std::string message;
};

}  // namespace clumpforge
