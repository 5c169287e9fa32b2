// workspace_gen: compute a reachability map (the paper's Algorithm 1) offline and write it as .npz.
//
//   workspace_gen --urdf snake16.urdf --base neck_end --tip head_tip --voxel 0.05 --directions 20
//       --rolls 4 --out map.npz
//
// Exit status: 0 on success; 2 for bad arguments or a bad robot description (nothing is written); 1 when
// the run fails (e.g. the map cannot be written: any old file at --out is left as it was). Errors are one
// line on stderr.
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <sstream>
#include <string>
#include <thread>
#include <utility>

#include "snakehead/model.hpp"
#include "snakehead/npz.hpp"
#include "snakehead/workspace.hpp"

namespace {

// The usage text; its defaults are read from WorkspaceOptions, so that they are written once (workspace.hpp).
std::string usage() {
  const snakehead::WorkspaceOptions d;
  auto num = [](double v) {
    std::ostringstream o;
    o << v;
    return o.str();
  };
  std::string text = R"(usage: workspace_gen --urdf FILE --base LINK --tip LINK --out MAP.npz [options]

Computes the reachability map of the chain BASE -> TIP (Algorithm 1 of the paper): voxels of the
cube of side 2 * reach centred on BASE that lie inside the boundary of random tip positions get the
index D = 100 * (points reached by TRAC-IK) / (points tried) over points spread on their inscribed
sphere (a point is reached when one of its rolled frames is solved; --each-roll counts frames).
The map keeps which points (or frames) were reached.

required:
  --urdf FILE            the robot description: a URDF file (xacro is not expanded here, and the
                         frames are the URDF's own: for a robot file, xacro or aligned frames use
                         snakehead workspace --robot ROBOT.toml)
  --base LINK            the chain's base link (the map's frame)
  --tip LINK             the chain's tip link
  --out FILE             output .npz (numpy.load reads it)
options:
  --voxel M              voxel edge in metres (default {voxel})
  --directions N         points per voxel sphere, Fibonacci lattice (default {directions})
  --rolls R              frames about the approach axis per point (default {rolls})
  --free-roll            instead of rolls: one IK call per point with the roll left free
  --each-roll            count every (point, roll) frame; by default a point counts as reached
                         when any of its rolls is solved (the paper's Algorithm 1)
  --approach-axis x|z    tip axis that approaches the sphere point (default x, the head's direction)
  --timeout S            IK budget per call in seconds (default {timeout})
  --epsilon E            IK tolerance (default {epsilon})
  --cloud-samples N      random configurations for the hull (default {cloud})
  --hull boundary|convex the voxels inside the cloud's boundary (the paper's boundary(P): an alpha
                         shape chosen as MATLAB's boundary() does; default) or its convex hull
  --shrink S             the boundary's shrink factor in [0, 1] (default {shrink}, MATLAB's default)
  --seed N               random seed (default {seed}); the map is a function of the seed
  --threads N            worker threads (default: all cores); does not change the map
  --shard i/N            compute only shard i of N (0 <= i < N); merge the N files afterwards
  --quiet                no progress line
  --help                 this text
)";
  const std::pair<const char*, std::string> fields[] = {
      {"{voxel}", num(d.voxel_size)},       {"{directions}", std::to_string(d.directions)},
      {"{rolls}", std::to_string(d.rolls)}, {"{timeout}", num(d.timeout)},
      {"{epsilon}", num(d.epsilon)},        {"{cloud}", std::to_string(d.cloud_samples)},
      {"{shrink}", num(d.shrink)},          {"{seed}", std::to_string(d.seed)}};
  for (const auto& [key, value] : fields) text.replace(text.find(key), std::string(key).size(), value);
  return text;
}

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

double parse_double(const std::string& flag, const std::string& s) {
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(v))
    throw UsageError(flag + " expects a number, got '" + s + "'");
  return v;
}

long long parse_int(const std::string& flag, const std::string& s) {
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(s.c_str(), &end, 10);
  if (s.empty() || *end != '\0' || errno == ERANGE) throw UsageError(flag + " expects an integer, got '" + s + "'");
  return v;
}

int parse_count(const std::string& flag, const std::string& s) {
  const long long v = parse_int(flag, s);
  if (v < -1000000000LL || v > 1000000000LL) throw UsageError(flag + " is out of range: " + s);
  return static_cast<int>(v);
}

std::string shell_quote(const std::string& s) {
  if (!s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_./=:,+@%") ==
                        std::string::npos)
    return s;
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// Fails early (before a long sweep) when the output cannot be written; leaves no file behind.
void check_writable(const std::string& path) {
  try {
    snakehead::check_output_path(path);
  } catch (const std::runtime_error& e) {
    throw UsageError(std::string("the output: ") + e.what());
  }
}

// A progress line on a terminal has no newline yet; an error message must start on a line of its own.
bool progress_line_open = false;

void report(const char* kind, const std::string& what) {
  std::string text = what;
  for (char& c : text)
    if (c == '\n' || c == '\r') c = ' ';  // one line, whatever the message holds
  std::cerr << (progress_line_open ? "\n" : "") << "workspace_gen: " << kind << ": " << text << "\n";
  progress_line_open = false;
}

}  // namespace

int main(int argc, char** argv) {
  // A write beyond the file-size limit (ulimit -f) then fails with EFBIG and is reported (the old map is
  // kept), instead of killing the process.
  std::signal(SIGXFSZ, SIG_IGN);
  std::string urdf, base, tip, out, command;
  snakehead::WorkspaceOptions opt;
  bool quiet = false, rolls_given = false, shrink_given = false;
  for (int k = 0; k < argc; ++k) command += (k ? " " : "") + shell_quote(k ? argv[k] : "workspace_gen");
  try {
    for (int k = 1; k < argc; ++k) {
      const std::string a = argv[k];
      auto value = [&]() -> std::string {
        if (k + 1 >= argc) throw UsageError(a + " needs a value");
        return argv[++k];
      };
      if (a == "--help" || a == "-h") {
        std::cout << usage();
        return 0;
      } else if (a == "--urdf") {
        urdf = value();
      } else if (a == "--base") {
        base = value();
      } else if (a == "--tip") {
        tip = value();
      } else if (a == "--out") {
        out = value();
      } else if (a == "--voxel") {
        opt.voxel_size = parse_double(a, value());
      } else if (a == "--directions") {
        opt.directions = parse_count(a, value());
      } else if (a == "--rolls") {
        opt.rolls = parse_count(a, value());
        rolls_given = true;
      } else if (a == "--each-roll") {
        opt.any_roll = false;
      } else if (a == "--free-roll") {
        opt.free_roll = true;
      } else if (a == "--approach-axis") {
        opt.approach = snakehead::parse_approach_axis(value());
      } else if (a == "--timeout") {
        opt.timeout = parse_double(a, value());
      } else if (a == "--epsilon") {
        opt.epsilon = parse_double(a, value());
      } else if (a == "--cloud-samples") {
        opt.cloud_samples = parse_count(a, value());
      } else if (a == "--hull") {
        opt.hull = snakehead::parse_hull_kind(value());
      } else if (a == "--shrink") {
        opt.shrink = parse_double(a, value());
        shrink_given = true;
      } else if (a == "--seed") {
        const long long s = parse_int(a, value());
        if (s < 0) throw UsageError("--seed must be >= 0");
        opt.seed = static_cast<std::uint64_t>(s);
      } else if (a == "--threads") {
        opt.threads = parse_count(a, value());
      } else if (a == "--shard") {
        const std::string s = value();
        const auto slash = s.find('/');
        if (slash == std::string::npos) throw UsageError("--shard expects i/N, got '" + s + "'");
        opt.shard_index = parse_count(a, s.substr(0, slash));
        opt.shard_count = parse_count(a, s.substr(slash + 1));
      } else if (a == "--quiet") {
        quiet = true;
      } else {
        throw UsageError("unknown argument '" + a + "' (see --help)");
      }
    }
    if (urdf.empty() || base.empty() || tip.empty() || out.empty())
      throw UsageError("--urdf, --base, --tip and --out are required (see --help)");
    const std::string xacro = ".xacro";
    if (urdf.size() >= xacro.size() && urdf.compare(urdf.size() - xacro.size(), xacro.size(), xacro) == 0)
      throw UsageError("--urdf " + urdf + " is a xacro file: workspace_gen reads URDF only; use snakehead workspace "
                       "--robot ROBOT.toml (it expands xacro), or expand it first (xacro FILE > FILE.urdf)");
    if (opt.free_roll && (rolls_given || !opt.any_roll))
      throw UsageError("--free-roll leaves the roll free: it takes neither --rolls nor --each-roll");
    if (shrink_given && opt.hull == snakehead::HullKind::Convex)
      throw UsageError("--shrink sets the boundary's shrink factor: it does not go with --hull convex");
    opt.validate();
    check_writable(out);
  } catch (const std::exception& e) {
    report("error", e.what());
    return 2;
  }

  try {
    const snakehead::ChainModel model = snakehead::ChainModel::from_urdf(urdf, base, tip);
    const bool tty = isatty(STDERR_FILENO) != 0;
    const auto t0 = std::chrono::steady_clock::now();
    int last_decile = -1;
    snakehead::ProgressCallback progress = [&](std::int64_t done, std::int64_t total) {
      if (quiet) return true;
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const double frac = total > 0 ? static_cast<double>(done) / total : 1.0;
      const int decile = static_cast<int>(frac * 10);
      if (!tty && decile == last_decile) return true;  // a log file gets a line per 10 %
      last_decile = decile;
      char line[160];
      std::snprintf(line, sizeof line, "workspace_gen: %lld/%lld voxels (%5.1f %%) %7.1f s%s",
                    static_cast<long long>(done), static_cast<long long>(total), 100 * frac, s,
                    done > 0 && done < total ? (", ~" + std::to_string(static_cast<int>(s * (1 / frac - 1))) +
                                                " s left").c_str()
                                             : "");
      std::cerr << (tty ? "\r" : "") << line << (tty ? "\x1b[K" : "\n") << std::flush;
      progress_line_open = tty;
      return true;
    };
    const snakehead::ReachabilityMap map = snakehead::compute_reachability(model, opt, progress);
    if (progress_line_open) std::cerr << "\n";
    progress_line_open = false;
    try {
      snakehead::save_npz(map, out, command);
    } catch (const std::exception& e) {  // the output was checked before the sweep: this is a failed run
      report("failed", e.what());
      return 1;
    }
    if (!quiet) {
      const Eigen::VectorXd d = map.indices();
      std::fprintf(stderr,
                   "workspace_gen: %zu voxels (shard %d/%d of %lld in the hull), %lld IK calls, %lld poses "
                   "rejected by reach bounds, %.1f s on %d threads, mean index %.2f -> %s\n",
                   map.voxel_ids.size(), opt.shard_index, opt.shard_count, static_cast<long long>(map.hull_voxels),
                   static_cast<long long>(map.ik_calls), static_cast<long long>(map.cheap_exits), map.seconds,
                   map.threads_used, d.size() ? d.mean() : 0.0, out.c_str());
    }
  } catch (const snakehead::InputError& e) {
    report("error", e.what());  // bad input (the robot, an option the grid or the chain rejects)
    return 2;
  } catch (const std::exception& e) {
    report("failed", e.what());  // e.g. the map could not be written (disk full); any old map is intact
    return 1;
  }
  return 0;
}
