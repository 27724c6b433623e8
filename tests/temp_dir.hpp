#pragma once
// A fresh folder under the system temp dir, removed with everything in it at scope exit, unless
// HIVESLAM_KEEP_TEST_DIRS is set (to read a failed test's node logs afterwards).
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>

namespace hiveslam::testing {

class TempDir {
 public:
  TempDir() {
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() /
            ("hiveslam_test_" + std::to_string(rd()) + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    if (std::getenv("HIVESLAM_KEEP_TEST_DIRS")) return;
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

}  // namespace hiveslam::testing
