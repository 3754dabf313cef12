// results/writers.hpp — the contract's result files, written atomically.
//
// Every writer streams into "<name>.tmp" in the target directory and renames
// it into place when complete, so a reader (the service, a user watching the
// directory) never sees a half-written file. Snapshots are written one at a
// time as the solver hands them over; nothing keeps them in memory.
// All writers throw std::runtime_error when a file cannot be written.
//
// One file per format in results/: summary.cpp (built as nlohmann's
// ordered_json), series.cpp, profiles.cpp, consolidation.cpp,
// reactions.cpp (JSON and CSV each, streamed: their arrays can hold
// millions of numbers; names are escaped by nlohmann, numbers written by
// hmpm/format.hpp), vtu.cpp (snapshots and the .pvd) and atomic_file.cpp.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "hmpm/api/job.hpp"
#include "hmpm/run.hpp"
#include "results/atomic_file.hpp"

namespace hmpm::api {

/// summary.json: status, message, steps, end_time, dt, particles, nodes,
/// solve_seconds, particle_steps_per_second, plus warnings, name,
/// hmpm_version, state_bytes, cost and the list of files.
void write_summary(const std::filesystem::path& path, const std::string& job_name,
                   const RunResult& run, const CostEstimate& cost,
                   const std::vector<std::string>& files);

/// series.json: {"time": [...], "particles": [{"index", "initial_position", <field>: rows}]}.
void write_series_json(const std::filesystem::path& path, const Series& series);

/// series.csv: header "time,p<index>_<field>[_<component>],..."; one row per time.
void write_series_csv(const std::filesystem::path& path, const Series& series);

/// reactions.json: {"time": [...], "boundaries": [{"index": i, "force": [[fx, ...], ...]}]},
/// one vector of `dimension` components per time for every boundary.
void write_reactions_json(const std::filesystem::path& path, const Reactions& reactions);

/// reactions.csv: header "time,b<index>_force_<x|y|z>,..."; one row per time.
void write_reactions_csv(const std::filesystem::path& path, const Reactions& reactions);

/// profiles.json: {"time": [...], "profiles": [{"index", "from", "to",
/// "points", "distance" (from `from`), "particles", "initial_positions",
/// <field>: one row per time, one value (scalar) or array of components per
/// point}]}: output.profiles, one entry per line.
void write_profiles_json(const std::filesystem::path& path, const std::vector<Series>& profiles,
                         const std::vector<ProfileGeometry>& geometry);

/// profiles.csv: "time,profile,point,distance,<field columns>", one row per
/// time, profile and point (columns as series.csv's without the particle
/// prefix; empty where a profile lacks the field).
void write_profiles_csv(const std::filesystem::path& path, const std::vector<Series>& profiles,
                        const std::vector<ProfileGeometry>& geometry);

/// consolidation.json: {"from", "t50", "t90", "time": [...], "degree": [...],
/// "average_excess_pore_pressure": [...], "volume": [...]}: output.consolidation.
void write_consolidation_json(const std::filesystem::path& path,
                              const RunResult::Consolidation& consolidation, double from);

/// consolidation.csv: "time,degree,average_excess_pore_pressure,volume", one
/// row per sample.
void write_consolidation_csv(const std::filesystem::path& path,
                             const RunResult::Consolidation& consolidation);

/// One snapshot as a VTK UnstructuredGrid (.vtu): one vertex cell per
/// particle, Points = positions, PointData = the snapshot's fields plus
/// volume and material; base64-encoded little-endian binary, uncompressed.
/// Vectors and tensors carry their component names (x, y, z; xx, yy, zz,
/// xy, yz, zx); each of `material_names` (index order) becomes a one-value
/// Int32 array of the field data named "material <name>" holding its index.
void write_snapshot_vtu(const std::filesystem::path& path, const Snapshot& snapshot,
                        const std::vector<std::string>& material_names = {});

/// ParaView collection listing (time, file name) pairs.
void write_pvd(const std::filesystem::path& path,
               const std::vector<std::pair<double, std::string>>& entries);

/// "snapshot_0007.vtu" for index 7.
std::string snapshot_file_name(int index);

}  // namespace hmpm::api
