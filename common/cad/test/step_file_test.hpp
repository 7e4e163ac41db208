#pragma once
// A test fixture for rigger_cad's tests: a temporary folder per test case, and shapes written to STEP and
// read back through the normal reader, so that every test goes through real files.

#include "rigger/cad/model.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace rigger::cad {

class StepFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("rigger_cad_test_" + std::to_string(::getpid()) + "_" +
                                                     ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  /// Writes the shape as STEP (millimetres) and reads it back.
  Model round_trip(const TopoDS_Shape& shape, const std::string& name) {
    const std::filesystem::path path = dir_ / (name + ".step");
    write_step(shape, name, path);
    return read_step_file(path);
  }

  std::filesystem::path write_text(const std::string& name, const std::string& text) {
    const std::filesystem::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }

  std::filesystem::path dir_;
};

}  // namespace rigger::cad
