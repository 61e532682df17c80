// What every program prints for --version: the project's version (CMake's project(VERSION)) and,
// when built from a git checkout, `git describe` at build time — "0.1.0 (git 68badda)".
#pragma once

namespace hamiltone::cli {

const char* versionText();

}  // namespace hamiltone::cli
