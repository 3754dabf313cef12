// results/atomic_file.hpp — a file that appears whole or not at all.
#pragma once

#include <filesystem>
#include <fstream>

namespace hmpm::api {

/// A file that appears under its final name only when commit() succeeds;
/// destroyed uncommitted, it removes its temporary file.
class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  std::ostream& stream() { return out_; }
  void commit();

 private:
  std::filesystem::path path_;
  std::filesystem::path tmp_;
  std::ofstream out_;
  bool committed_ = false;
};

}  // namespace hmpm::api
