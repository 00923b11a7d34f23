#pragma once
namespace clumpforge {
/// The tool's version, recorded in every file it writes.
inline constexpr const char* kVersion = CLUMPFORGE_VERSION;
}  // namespace clumpforge
