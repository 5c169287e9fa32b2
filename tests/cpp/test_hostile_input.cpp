// Hostile and broken input (issue 14): durations that would overflow a clock deadline, sizes that would
// exhaust memory, robot descriptions that would crash urdfdom's parser or lose data silently, urdfdom's
// console output, and files that must survive a failed write. Every case is an InputError whose message
// says what was wrong, never a crash, a hang or a silently wrong answer.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <dirent.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <thread>

#include "snakehead/kinematics.hpp"
#include "snakehead/limits.hpp"
#include "snakehead/npz.hpp"
#include "snakehead/trac_ik.hpp"
#include "snakehead/urdf_input.hpp"
#include "snakehead/workspace.hpp"

#include <console_bridge/console.h>

using namespace snakehead;

namespace {

const std::string kSnake = std::string(SNAKEHEAD_URDF_DIR) + "/snake16.urdf";

std::shared_ptr<const ChainModel> head7() {
  static auto m = std::make_shared<const ChainModel>(ChainModel::from_urdf(kSnake, "neck_end", "head_tip"));
  return m;
}

// Runs `fn`, which must throw InputError; returns its message ("" and a test failure otherwise).
template <class Fn>
std::string input_error(Fn fn) {
  try {
    fn();
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got another exception: " << e.what();
    return "";
  }
  ADD_FAILURE() << "expected InputError, nothing was thrown";
  return "";
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

// ---------------------------------------------------------------------------------------------------------
// Durations: a finite but huge timeout overflowed the steady_clock deadline (64-bit ns), so every call
// gave up at once and reachable targets were reported unreachable.

TEST(HostileTimeout, HugeTimeoutsAreRejectedNamingTheField) {
  const auto model = head7();
  const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(model->n_joints());
  const Eigen::Isometry3d target = forward_kinematics(*model, Eigen::VectorXd::Constant(model->n_joints(), 0.2));
  for (double t : {86400.5, 1e9, 1e10, 1e19, 1e300, std::numeric_limits<double>::max()}) {
    SCOPED_TRACE(t);
    TracIKOptions o;
    o.timeout = t;
    std::string msg = input_error([&] { check_options(o); });
    EXPECT_TRUE(contains(msg, "timeout") && contains(msg, "86400")) << msg;
    msg = input_error([&] { TracIK(model, o); });
    EXPECT_TRUE(contains(msg, "timeout")) << msg;
    TracIK ik(model);
    input_error([&] { ik.solve_ex(target, q0, o); });
    Eigen::VectorXd q;
    msg = input_error([&] { kdl_nr_jl_ik(*model, target, q0, q, t); });
    EXPECT_TRUE(contains(msg, "timeout")) << msg;
    WorkspaceOptions w;
    w.timeout = t;
    msg = input_error([&] { w.validate(); });
    EXPECT_TRUE(contains(msg, "timeout") && contains(msg, "86400")) << msg;
  }
}

TEST(HostileTimeout, LongestAllowedTimeoutStillSolves) {
  // A day-long budget: the deadline is far away, so a reachable target is found (Speed returns at the
  // first solution), seeded or not; before the fix a seeded call's guard (10 x timeout) overflowed at 1e9 s.
  const auto model = head7();
  const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(model->n_joints());
  const Eigen::Isometry3d target = forward_kinematics(*model, Eigen::VectorXd::Constant(model->n_joints(), 0.3));
  for (bool seeded : {false, true}) {
    TracIKOptions o;
    o.timeout = limits::kMaxTimeoutSeconds;
    if (seeded) o.seed = 3;
    TracIK ik(model, o);
    Eigen::VectorXd q;
    EXPECT_TRUE(ik.solve(target, q0, q)) << "seeded " << seeded;
  }
  Eigen::VectorXd q;
  Eigen::VectorXd near = Eigen::VectorXd::Constant(model->n_joints(), 0.28);
  EXPECT_TRUE(kdl_nr_jl_ik(*model, target, near, q, limits::kMaxTimeoutSeconds));
}

TEST(HostileTimeout, DeadlinesSaturateInsteadOfOverflowing) {
  using Clock = std::chrono::steady_clock;
  const auto now = Clock::now();
  EXPECT_EQ(deadline_after(now, 1e300), Clock::time_point::max());
  EXPECT_EQ(deadline_after(now, 1e10), Clock::time_point::max());
  EXPECT_EQ(deadline_after(now, std::numeric_limits<double>::infinity()), Clock::time_point::max());
  EXPECT_EQ(deadline_after(now, 0.0), now);
  EXPECT_EQ(deadline_after(now, -5.0), now);
  EXPECT_EQ(deadline_after(now, std::nan("")), now);  // never "no deadline" by accident
  const auto day = deadline_after(now, 86400.0);
  EXPECT_NEAR(std::chrono::duration<double>(day - now).count(), 86400.0, 1e-6);
  EXPECT_GT(deadline_after(now, 1e9), now);
}

// ---------------------------------------------------------------------------------------------------------
// Sizes: numbers that become allocations are bounded before anything is allocated, with a message that
// names the field and the limit (a voxel of 1e-9 m asked for 10^27 voxels; directions x rolls overflowed int).

TEST(HostileSizes, SweepOptionsBeyondTheirLimitsNameFieldAndLimit) {
  auto message = [](auto edit) {
    WorkspaceOptions o;
    edit(o);
    return input_error([&] { o.validate(); });
  };
  std::string m = message([](WorkspaceOptions& o) { o.directions = 1'000'000'000; });
  EXPECT_TRUE(contains(m, "directions") && contains(m, std::to_string(limits::kMaxDirections))) << m;
  m = message([](WorkspaceOptions& o) { o.rolls = 1'000'000; });
  EXPECT_TRUE(contains(m, "rolls") && contains(m, std::to_string(limits::kMaxRolls))) << m;
  m = message([](WorkspaceOptions& o) { o.directions = 100'000, o.rolls = 100'000; });  // the product overflowed int
  EXPECT_TRUE(contains(m, "directions")) << m;
  m = message([](WorkspaceOptions& o) { o.directions = 1000, o.rolls = 100; });
  EXPECT_TRUE(contains(m, "frames per voxel") && contains(m, std::to_string(limits::kMaxFramesPerVoxel))) << m;
  m = message([](WorkspaceOptions& o) { o.cloud_samples = 2'000'000'000; });
  EXPECT_TRUE(contains(m, "cloud_samples") && contains(m, std::to_string(limits::kMaxCloudSamples))) << m;
  m = message([](WorkspaceOptions& o) { o.threads = 1'000'000; });
  EXPECT_TRUE(contains(m, "threads") && contains(m, std::to_string(limits::kMaxThreads))) << m;
  // A tiny voxel passes here (the grid depends on the chain; see below). Free roll: rolls do not count.
  WorkspaceOptions free_roll;
  free_roll.free_roll = true;
  free_roll.rolls = 1'000'000;
  free_roll.directions = limits::kMaxDirections;
  EXPECT_NO_THROW(free_roll.validate());
}

TEST(HostileSizes, TinyVoxelsAreRejectedBeforeTheSweep) {
  const auto model = head7();
  WorkspaceOptions o;
  o.cloud_samples = 200;
  for (double voxel : {1e-9, 1e-300, 2.0 * model->reach() / (limits::kMaxVoxelsPerAxis + 1)}) {
    o.voxel_size = voxel;
    const std::string m = input_error([&] { compute_reachability(*model, o); });
    EXPECT_TRUE(contains(m, "voxel size") && contains(m, std::to_string(limits::kMaxVoxelsPerAxis))) << m;
  }
  EXPECT_NO_THROW(VoxelGrid::around(Eigen::Vector3d::Zero(), 1.0, 1.0 / limits::kMaxVoxelsPerAxis));
  std::string m = input_error([&] { fibonacci_directions(2'000'000'000); });
  EXPECT_TRUE(contains(m, std::to_string(limits::kMaxDirections))) << m;
  m = input_error([&] { sample_tip_positions(*model, 2'000'000'000, 1); });
  EXPECT_TRUE(contains(m, std::to_string(limits::kMaxCloudSamples))) << m;
}

// ---------------------------------------------------------------------------------------------------------
// Robot descriptions: checked before urdfdom's recursive XML parser (TinyXML) sees them.

namespace {

std::string nested(int depth, const std::string& open = "<a>", const std::string& close = "</a>") {
  std::string s = "<robot name='r'>";
  for (int k = 0; k < depth; ++k) s += open;
  for (int k = 0; k < depth; ++k) s += close;
  return s + "</robot>";
}

// A two-link robot with one revolute joint; `link_b` is the second link's body.
std::string two_links(const std::string& link_b, const std::string& joint_extra = "") {
  return "<?xml version='1.0'?><robot name='r'><link name='a'/>" + link_b +
         "<joint name='j' type='revolute'><parent link='a'/><child link='b'/><axis xyz='0 0 1'/>"
         "<limit lower='-1' upper='1' effort='1' velocity='1'" + joint_extra + "/></joint></robot>";
}

std::string link_b(const std::string& mass, const std::string& inertia, const std::string& box = "0.1 0.1 0.1") {
  return "<link name='b'><inertial><mass value='" + mass + "'/><inertia " + inertia +
         "/></inertial><collision><geometry><box size='" + box + "'/></geometry></collision></link>";
}

const std::string kGoodInertia = "ixx='1e-3' ixy='0' ixz='0' iyy='1e-3' iyz='0' izz='1e-3'";

std::string temp_path(const std::string& name) { return ::testing::TempDir() + "/snakehead_hostile_" + name; }

}  // namespace

TEST(HostileUrdf, DeepNestingIsRejectedBeforeTheParser) {
  // 40,000 levels (280 kB) overflowed TinyXML's stack (SIGSEGV).
  const std::string deep = nested(40000);
  EXPECT_LT(deep.size(), 300'000u);
  std::string m = input_error([&] { ChainModel::from_urdf(deep, "a", "b"); });
  EXPECT_TRUE(contains(m, "nested") && contains(m, std::to_string(limits::kMaxUrdfDepth))) << m;
  // The limit counts the robot element too: robot + 99 levels pass the scan, robot + 100 do not.
  EXPECT_NO_THROW(check_urdf_document(nested(limits::kMaxUrdfDepth - 1)));
  EXPECT_THROW(check_urdf_document(nested(limits::kMaxUrdfDepth)), InputError);
  // Self-closed elements, comments, CDATA and declarations do not nest.
  EXPECT_NO_THROW(check_urdf_document(nested(5000, "<a/>", "")));
  EXPECT_NO_THROW(check_urdf_document(nested(5000, "<!-- <a> -->", "")));
  EXPECT_NO_THROW(check_urdf_document(nested(5000, "<![CDATA[<a>]]>", "")));
  // ...but the scan reads the text as TinyXML does: a quoted "/>" does not close a tag, attributes may be
  // unquoted, end tags take white space, and a declaration's version may hold '>'.
  EXPECT_THROW(check_urdf_document(nested(200, "<a x=\"/>\">")), InputError);
  EXPECT_THROW(check_urdf_document(nested(200, "<a x=y>", "</a >")), InputError);
  EXPECT_THROW(check_urdf_document("<?xml version='>'?>" + nested(200)), InputError);
  EXPECT_THROW(check_urdf_document("<?xml version='1' ?>\n<!DOCTYPE robot>" + nested(200)), InputError);
  // TinyXML's numeric references search for the next ';' and skip what lies before it, end tags included:
  // only well-formed ones pass.
  EXPECT_NO_THROW(check_urdf_document("<robot name='r&#x41;&#66;'>&#x263A;&amp;&#10;</robot>"));
  m = input_error([&] { check_urdf_document(nested(3, "<a>&#x", "</a>x1;")); });
  EXPECT_TRUE(contains(m, "character reference")) << m;
  EXPECT_THROW(check_urdf_document("<robot name='&#12'></robot>"), InputError);
}

TEST(HostileUrdf, SizeNulAndEncodingAreChecked) {
  std::string big = "<robot name='r'>" + std::string(limits::kMaxUrdfBytes, ' ') + "</robot>";
  std::string m = input_error([&] { ChainModel::from_urdf(big, "a", "b"); });
  EXPECT_TRUE(contains(m, "bytes") && contains(m, std::to_string(limits::kMaxUrdfBytes))) << m;
  m = input_error([&] { check_urdf_document(std::string("<robot name='r'>\n\0</robot>", 26)); });
  EXPECT_TRUE(contains(m, "NUL") && contains(m, "line 2")) << m;
  m = input_error([&] { check_urdf_document("<robot name='\xC3('></robot>"); });
  EXPECT_TRUE(contains(m, "UTF-8")) << m;
  EXPECT_THROW(check_urdf_document("<robot name='r'>\xEF\xBB\xBF</robot>"), InputError);
  EXPECT_NO_THROW(check_urdf_document("\xEF\xBB\xBF<robot name='r\xC3\xA9'></robot>"));  // a leading BOM is fine
}

TEST(HostileUrdf, OnlyRegularFilesOfBoundedSizeAreRead) {
  // /dev/zero read forever; a FIFO waited for a writer; a directory gave a confusing parse error.
  std::string m = input_error([] { ChainModel::from_urdf("/dev/zero", "a", "b"); });
  EXPECT_TRUE(contains(m, "/dev/zero") && contains(m, "character device")) << m;
  const std::string fifo = temp_path("fifo.urdf");
  std::remove(fifo.c_str());
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  m = input_error([&] { ChainModel::from_urdf(fifo, "a", "b"); });
  EXPECT_TRUE(contains(m, "FIFO")) << m;
  std::remove(fifo.c_str());
  m = input_error([] { ChainModel::from_urdf(::testing::TempDir(), "a", "b"); });
  EXPECT_TRUE(contains(m, "directory")) << m;
  m = input_error([] { ChainModel::from_urdf("/no/such/robot.urdf", "a", "b"); });
  EXPECT_TRUE(contains(m, "No such file")) << m;
  const std::string huge = temp_path("huge.urdf");  // sparse: no disk space used
  {
    std::ofstream f(huge);
  }
  ASSERT_EQ(truncate(huge.c_str(), static_cast<off_t>(limits::kMaxUrdfBytes) + 1), 0);
  m = input_error([&] { read_urdf_file(huge); });
  EXPECT_TRUE(contains(m, "bytes")) << m;
  std::remove(huge.c_str());
  EXPECT_EQ(read_urdf_file(kSnake).substr(0, 5), "<?xml");
}

TEST(HostileUrdf, UrdfdomMessagesBecomeTheErrorAndAreNeverPrinted) {
  const std::string no_limits =
      "<robot name='r'><link name='a'/><link name='b'/><joint name='j1' type='revolute'>"
      "<parent link='a'/><child link='b'/><axis xyz='0 0 1'/></joint></robot>";
  // A successful parse that makes urdfdom warn (an undefined material) must be quiet too.
  const std::string warns = two_links("<link name='b'><visual><geometry><box size='1 1 1'/></geometry>"
                                      "<material name='nowhere'/></visual></link>");
  ::testing::internal::CaptureStdout();
  ::testing::internal::CaptureStderr();
  const std::string m = input_error([&] { ChainModel::from_urdf(no_limits, "a", "b"); });
  const std::string tinyxml = input_error([] { ChainModel::from_urdf("<robot name='r'><link name='a'></robot>", "a", "b"); });
  EXPECT_NO_THROW(ChainModel::from_urdf(warns, "a", "b"));
  const std::string out = ::testing::internal::GetCapturedStdout();
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_TRUE(contains(m, "j1") && contains(m, "does not specify limits")) << m;
  EXPECT_TRUE(contains(tinyxml, "end tag")) << tinyxml;  // TinyXML's own description
  EXPECT_EQ(out, "");
  EXPECT_EQ(err, "");
}

namespace {
struct RecordingHandler : console_bridge::OutputHandler {
  void log(const std::string& text, console_bridge::LogLevel, const char*, int) override { seen.push_back(text); }
  std::vector<std::string> seen;
};
}  // namespace

TEST(HostileUrdf, CaptureIsPerThreadAndRestoresTheHandler) {
  // Eight threads parse broken robots at once, each with its own joint name: each error holds its own
  // joint's message and no other's.
  std::vector<std::string> messages(8);
  std::vector<std::thread> threads;
  for (int t = 0; t < 8; ++t)
    threads.emplace_back([t, &messages] {
      const std::string joint = "joint_of_thread_" + std::to_string(t);
      const std::string xml = "<robot name='r'><link name='a'/><link name='b'/><joint name='" + joint +
                              "' type='prismatic'><parent link='a'/><child link='b'/></joint></robot>";
      for (int k = 0; k < 20; ++k) {
        try {
          ChainModel::from_urdf(xml, "a", "b");
        } catch (const InputError& e) {
          messages[t] = e.what();
        }
      }
    });
  for (auto& th : threads) th.join();
  for (int t = 0; t < 8; ++t) {
    EXPECT_TRUE(contains(messages[t], "joint_of_thread_" + std::to_string(t))) << messages[t];
    for (int u = 0; u < 8; ++u)
      if (u != t) EXPECT_FALSE(contains(messages[t], "joint_of_thread_" + std::to_string(u) + "]")) << messages[t];
  }
  // The handler installed before is back afterwards, and gets what others log.
  RecordingHandler recording;
  console_bridge::OutputHandler* before = console_bridge::getOutputHandler();
  console_bridge::useOutputHandler(&recording);
  EXPECT_THROW(ChainModel::from_urdf("<robot name='r'/>", "a", "b"), InputError);
  EXPECT_EQ(console_bridge::getOutputHandler(), &recording);
  CONSOLE_BRIDGE_logError("a message of someone else");
  console_bridge::useOutputHandler(before);
  ASSERT_EQ(recording.seen.size(), 1u);
  EXPECT_EQ(recording.seen[0], "a message of someone else");
}

TEST(HostileUrdf, MalformedInertialOrCollisionNamesTheLinkAndElement) {
  // urdfdom dropped these elements (and printed to the console), leaving the link massless or boxless.
  struct Case {
    std::string link, what;
  };
  const std::vector<Case> cases = {
      {link_b("0,2", kGoodInertia), "inertial"},
      {link_b("nan", kGoodInertia), "inertial"},
      {link_b("0.2", "ixx='1e-3' ixy='0' ixz='0' iyy='inf' iyz='0' izz='1e-3'"), "inertial"},
      {link_b("0.2", kGoodInertia, "0,1 0.1 0.1"), "collision"},
      {link_b("0.2", kGoodInertia, "0.1 nan 0.1"), "collision"},
      {link_b("-0.2", kGoodInertia), "mass"},
      {link_b("0.2", "ixx='1e-3' ixy='2e-3' ixz='0' iyy='1e-3' iyz='0' izz='1e-3'"), "positive semidefinite"},
      {link_b("0.2", "ixx='1e-3' ixy='0' ixz='0' iyy='1e-3' iyz='0' izz='5e-3'"), "triangle"},
      {link_b("0.2", kGoodInertia, "0.1 0 0.1"), "box size"},
      {link_b("0.2", kGoodInertia, "0.1 -0.1 0.1"), "box size"},
      {"<link name='b'><collision><geometry><sphere radius='-1'/></geometry></collision></link>", "sphere"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.link);
    const std::string m = input_error([&] { ChainModel::from_urdf(two_links(c.link), "a", "b"); });
    EXPECT_TRUE(contains(m, "b") && contains(m, c.what)) << m;
  }
  // The link is named (urdfdom's "Link [b]" or ours "link 'b'").
  const std::string m = input_error([&] { ChainModel::from_urdf(two_links(link_b("0,2", kGoodInertia)), "a", "b"); });
  EXPECT_TRUE(contains(m, "Link [b]") && contains(m, "0,2")) << m;
  EXPECT_TRUE(contains(input_error([&] { ChainModel::from_urdf(two_links(link_b("-1", kGoodInertia)), "a", "b"); }),
                       "link 'b' <inertial>"));
  // Joint limits of the wrong sign.
  const std::string bad_velocity = "<?xml version='1.0'?><robot name='r'><link name='a'/><link name='b'/>"
                                   "<joint name='j' type='revolute'><parent link='a'/><child link='b'/>"
                                   "<limit lower='-1' upper='1' effort='1' velocity='-3'/></joint></robot>";
  EXPECT_TRUE(contains(input_error([&] { ChainModel::from_urdf(bad_velocity, "a", "b"); }), "velocity"));
  // Sound data passes: a massless link, a point mass, a thin plate.
  EXPECT_NO_THROW(ChainModel::from_urdf(two_links("<link name='b'/>"), "a", "b"));
  EXPECT_NO_THROW(ChainModel::from_urdf(two_links(link_b("0.2", "ixx='0' ixy='0' ixz='0' iyy='0' iyz='0' izz='0'")),
                                        "a", "b"));
  EXPECT_NO_THROW(ChainModel::from_urdf(two_links(link_b("0.2", "ixx='1e-3' ixy='0' ixz='0' iyy='2e-3' iyz='0' izz='3e-3'")),
                                        "a", "b"));
}

TEST(HostileUrdf, KinematicHashIsUnchangedAndTheBodiesHaveTheirOwn) {
  // The shipped maps (python/snakehead/data/*.npz) record these kinematic hashes.
  const ChainModel head = ChainModel::from_urdf(kSnake, "neck_end", "head_tip");
  EXPECT_EQ(head.hash(), "9581ed36d7fff8a5");
  EXPECT_EQ(ChainModel::from_urdf(kSnake, "link_10", "head_tip").hash(), "0f32da7f939f69c3");
  // The default robot weighs 3.2 kg (0.2 kg per 0.0865 m of body, DESIGN.md).
  const ChainModel body = ChainModel::from_urdf(kSnake, "link_0", "head_tip");
  EXPECT_NEAR(body.total_mass(), 3.2, 1e-9);
  // A mass changes the bodies' digest, not the kinematic one; a joint origin changes the kinematic one.
  const std::string text = read_urdf_file(kSnake);
  std::string heavier = text;
  const auto at = heavier.find("<mass value=\"0.2\"");
  ASSERT_NE(at, std::string::npos);
  heavier.replace(at, 17, "<mass value=\"0.3\"");
  const ChainModel heavy = ChainModel::from_urdf(heavier, "link_0", "head_tip");
  EXPECT_EQ(heavy.hash(), body.hash());
  EXPECT_NE(heavy.body_hash(), body.body_hash());
  EXPECT_NEAR(heavy.total_mass(), 3.3, 1e-9);
  EXPECT_EQ(ChainModel::from_urdf(kSnake, "link_0", "head_tip").body_hash(), body.body_hash());
  EXPECT_EQ(ChainModel::from_urdf(two_links("<link name='b'/>"), "a", "b").total_mass(), 0.0);
}

// ---------------------------------------------------------------------------------------------------------
// Errors in worker threads reach the caller as the same exception.

namespace {
struct ThrowingSolver : PoseSolver {
  bool solve(const Eigen::Isometry3d&, const Eigen::VectorXd&, std::uint64_t, double, Eigen::VectorXd&) override {
    throw InputError("thrown in a worker thread");
  }
};
}  // namespace

TEST(HostileThreads, WorkerExceptionsReachTheCaller) {
  WorkspaceOptions o;
  o.voxel_size = 0.2;
  o.directions = 2;
  o.rolls = 1;
  o.cloud_samples = 200;
  o.threads = 4;
  const PoseSolverFactory throwing = [](const ChainModel&, const WorkspaceOptions&) {
    return std::make_unique<ThrowingSolver>();
  };
  const std::string m = input_error([&] { compute_reachability(*head7(), o, nullptr, throwing); });
  EXPECT_EQ(m, "thrown in a worker thread");
}

// ---------------------------------------------------------------------------------------------------------
// Files: written under a temporary name and renamed, so a failed write keeps the old file and leaves no
// partial one.

namespace {

std::vector<std::string> directory_entries(const std::string& dir) {
  std::vector<std::string> names;
  if (DIR* d = opendir(dir.c_str())) {
    while (dirent* e = readdir(d))
      if (std::string(e->d_name) != "." && std::string(e->d_name) != "..") names.push_back(e->d_name);
    closedir(d);
  }
  std::sort(names.begin(), names.end());
  return names;
}

std::string file_text(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// A file-size limit (ulimit -f) for the scope, with SIGXFSZ ignored so that the write fails with EFBIG.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    getrlimit(RLIMIT_FSIZE, &saved_);
    old_handler_ = signal(SIGXFSZ, SIG_IGN);
    rlimit r = saved_;
    r.rlim_cur = bytes;
    setrlimit(RLIMIT_FSIZE, &r);
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &saved_);
    signal(SIGXFSZ, old_handler_);
  }

 private:
  rlimit saved_{};
  void (*old_handler_)(int) = nullptr;
};

}  // namespace

TEST(HostileFiles, FailedNpzWriteKeepsTheOldFile) {
  const std::string dir = temp_path("npz_dir");
  mkdir(dir.c_str(), 0700);
  const std::string path = dir + "/map.npz";
  {
    std::ofstream f(path);
    f << "the old map";
  }
  NpzWriter w;
  w.add_f64("big", std::vector<double>(100000, 1.0), {100000});
  {
    FileSizeLimit limit(4096);
    try {
      w.write(path);
      ADD_FAILURE() << "the write should fail beyond the file-size limit";
    } catch (const std::runtime_error& e) {
      EXPECT_TRUE(contains(e.what(), "File too large")) << e.what();
    }
  }
  EXPECT_EQ(file_text(path), "the old map");
  EXPECT_EQ(directory_entries(dir), std::vector<std::string>{"map.npz"});
  w.write(path);  // and without the limit it replaces the file
  EXPECT_EQ(file_text(path), w.bytes());
  EXPECT_EQ(directory_entries(dir), std::vector<std::string>{"map.npz"});
  std::remove(path.c_str());
  rmdir(dir.c_str());
}

TEST(HostileFiles, OutputsThatAreNotFilesAreRefused) {
  const std::string fifo = temp_path("out_fifo.npz");
  std::remove(fifo.c_str());
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  NpzWriter w;
  w.add_scalar("x", 1.0);
  EXPECT_THROW(check_output_path(fifo), std::runtime_error);  // used to block opening it
  EXPECT_THROW(w.write(fifo), std::runtime_error);            // renaming would replace it
  struct stat st {};
  ASSERT_EQ(stat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  std::remove(fifo.c_str());
  EXPECT_THROW(check_output_path(::testing::TempDir()), std::runtime_error);
  EXPECT_THROW(check_output_path("/no/such/dir/map.npz"), std::runtime_error);
  const std::string dir = temp_path("check_dir");
  mkdir(dir.c_str(), 0700);
  EXPECT_NO_THROW(check_output_path(dir + "/map.npz"));
  EXPECT_TRUE(directory_entries(dir).empty());  // the trial file is gone
  rmdir(dir.c_str());
}
