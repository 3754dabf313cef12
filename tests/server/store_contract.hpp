// store_contract.hpp — the contract every JobStore backend passes.
//
// The tests in store_contract.cpp are value-parameterised over a
// `StoreBackend`: a name and a function that opens the backend's store on a
// fresh scratch location (a folder for SQLite; the PostgreSQL backend
// derives a schema of the test database from it) with the test's clock (`advance` ages jobs
// without sleeping). A backend runs the suite with one line:
//   INSTANTIATE_TEST_SUITE_P(Sqlite, StoreContract, ::testing::Values(StoreBackend{...}));
// Everything here goes through the JobStore interface only: what a store
// must do, not how. Backend details (files, migrations, locks) have their own
// tests beside the backend's instantiation (test_sqlite_store.cpp).
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <ostream>
#include <string>

#include "hmpm/server/store.hpp"

namespace hmpm::server::testing {

struct StoreBackend {
  std::string name;
  /// Opens the store kept at `scratch` (the same location each call),
  /// reading the time from `clock`.
  std::unique_ptr<JobStore> (*open)(const std::filesystem::path& scratch, WallClock clock);
  /// Why the backend cannot run here ("" or null: it can); the tests skip
  /// with that reason. A backend that must run (PostgreSQL under CI) says ""
  /// and lets open() fail instead.
  std::string (*unavailable)() = nullptr;
};

/// Prints the backend's name in failure messages.
// NOLINTNEXTLINE(readability-identifier-naming): GoogleTest looks the printer up by this name.
inline void PrintTo(const StoreBackend& backend, std::ostream* os) {
  *os << backend.name;
}

/// Prints the backend's name in test names.
inline std::string backend_name(const ::testing::TestParamInfo<StoreBackend>& info) {
  return info.param.name;
}

class StoreContract : public ::testing::TestWithParam<StoreBackend> {
 protected:
  void SetUp() override;
  void TearDown() override;

  /// The store under test (opened on first use).
  JobStore& store();
  /// Closes the store (as a stopping process does); the next store() reopens it.
  void close();
  /// The store's clock: the system clock plus what advance() added.
  std::chrono::system_clock::time_point now() const;
  /// Moves the store's clock forward by `by`.
  void advance(std::chrono::system_clock::duration by);

  /// A new job named `name`, with a unique id.
  static NewJob job(const std::string& name, const std::string& key = "",
                    const std::string& body_hash = "");

  /// A new ensemble of `samples` jobs named sample-0, sample-1, ... (unique ids).
  static NewEnsemble ensemble(int samples, const std::string& key = "",
                              const std::string& body_hash = "");

  /// This process's claimant: a lease that stays live for the whole test.
  static Claimant live();
  /// A claimant whose leases have lapsed as soon as they are taken (a dead process).
  static Claimant dead(const std::string& instance = "dead-instance");

  std::filesystem::path scratch_;
  std::chrono::system_clock::duration offset_{0};
  std::unique_ptr<JobStore> store_;
};

}  // namespace hmpm::server::testing
