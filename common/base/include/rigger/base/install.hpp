#pragma once
/// @file
/// Where the running program is installed: files it needs at run time (the DDS configuration, the
/// deployment's configurations, the cell, the recipes) are found relative to its own executable, never
/// through a path of the source tree compiled in.
///
/// Layout (the same in an installed prefix and in the build tree, which CMake stages alike):
///   <prefix>/bin/<program>             services, riggerctl, rigger-compose
///   <prefix>/tests/, <prefix>/bench/   test and benchmark binaries (build tree only)
///   <prefix>/share/rigger/             cyclonedds.xml, deploy/, recipes/, …

#include <filesystem>

namespace rigger {

/// The running executable (from /proc/self/exe); empty when it cannot be read.
std::filesystem::path executable_path();

/// The installation's data folder `<prefix>/share/rigger`, where `<prefix>` is the folder above the
/// one holding `executable` (default: the running executable). Empty when `executable` is empty.
std::filesystem::path data_dir(const std::filesystem::path& executable = executable_path());

}  // namespace rigger
