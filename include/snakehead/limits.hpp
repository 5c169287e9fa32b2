// Limits on what callers may ask for, in one place: durations that become clock deadlines, sizes that
// become allocations, and robot descriptions before they reach urdfdom's recursive XML parser.
//
// Each limit is far above any sensible use and far below what would overflow, exhaust memory or crash;
// a value beyond one is bad input (InputError naming the field and the limit), never silently clamped.
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

namespace snakehead {

namespace limits {

// Durations (s). One IK call, or one per-pose budget of a sweep, longer than a day is a mistake; a
// steady_clock deadline (64-bit nanoseconds) overflows beyond about 292 years.
constexpr double kMaxTimeoutSeconds = 86400.0;

// Robot descriptions (URDF). The largest real URDFs are a few hundred kB; TinyXML (urdfdom's parser)
// recurses once per element nesting level, and URDF needs about six levels.
constexpr std::size_t kMaxUrdfBytes = 8u << 20;  // 8 MiB
constexpr int kMaxUrdfDepth = 100;               // element nesting levels

// TRAC-IK: its SQP half (NLopt's SLSQP) needs memory growing with the square of the joint count.
constexpr int kMaxIKJoints = 1000;

// Workspace sweeps (per-thread buffers hold a run of voxels times the frames of a voxel).
constexpr int kMaxVoxelsPerAxis = 256;           // a grid of at most 256^3 = 16.8 million voxels
constexpr int kMaxDirections = 4096;             // points on a voxel's sphere
constexpr int kMaxRolls = 360;                   // frames about the approach axis per point
constexpr int kMaxFramesPerVoxel = 4096;         // directions x rolls
constexpr int kMaxCloudSamples = 10'000'000;     // configurations sampled for the hull
constexpr int kMaxThreads = 256;

// Terrains (include/snakehead/terrain.hpp): each triangle keeps about 200 bytes (its normals, box and tree node).
constexpr long kMaxTerrainCells = 1L << 20;       // heightfield cells (two triangles each): 1024 x 1024
constexpr long kMaxTerrainTriangles = 2'000'000;  // mesh triangles

}  // namespace limits

// A number as a short text for messages (%g: "1e+300", "0.0003"; std::to_string gives 300 digits or "0.000000").
std::string number_text(double x);

// Throws InputError unless 0 < seconds <= limits::kMaxTimeoutSeconds; the message names `field`.
void check_timeout(double seconds, const std::string& field = "timeout");

// start + seconds on the steady clock, saturated at the clock's largest time point instead of
// overflowing (so a deadline is never in the past because the duration was large). seconds >= 0.
std::chrono::steady_clock::time_point deadline_after(std::chrono::steady_clock::time_point start, double seconds);

}  // namespace snakehead
