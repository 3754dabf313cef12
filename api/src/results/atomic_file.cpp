// results/atomic_file.cpp — see results/atomic_file.hpp.
#include "results/atomic_file.hpp"

#include <stdexcept>
#include <system_error>

namespace hmpm::api {

namespace fs = std::filesystem;

AtomicFile::AtomicFile(fs::path path) : path_(std::move(path)), tmp_(path_) {
  tmp_ += ".tmp";
  out_.open(tmp_, std::ios::binary | std::ios::trunc);
  if (!out_) throw std::runtime_error("cannot create " + tmp_.string());
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  out_.close();
  std::error_code ec;
  fs::remove(tmp_, ec);
}

void AtomicFile::commit() {
  out_.flush();
  if (!out_) throw std::runtime_error("cannot write " + tmp_.string());
  out_.close();
  std::error_code ec;
  fs::rename(tmp_, path_, ec);
  if (ec)
    throw std::runtime_error("cannot rename " + tmp_.string() + " to " + path_.string() + ": " +
                             ec.message());
  committed_ = true;
}

}  // namespace hmpm::api
