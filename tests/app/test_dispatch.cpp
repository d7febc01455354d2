// Beyond one machine: the same per-building jobs dispatched by GNU Parallel (over the local host,
// as --sshloginfile would to others) and by a Slurm job array on a throwaway one-node cluster on
// loopback (tests/slurm_one_node.sh) give outputs identical to the local batch.mk run. Each test
// skips when its engine is not installed (.ci/run installs them: deps.sh --with-cluster).
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include "support/batch_fixtures.h"

using namespace lodrefine::batch_fixtures;

namespace {

bool installed(const std::string& programs) {
  return shell("for p in " + programs + "; do command -v $p > /dev/null 2>&1 || exit 1; done") == 0;
}

// A port free on 127.0.0.1 right now (the kernel's pick).
int free_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof a;
  if (fd < 0 || ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) != 0)
    return 0;
  const int port = ntohs(a.sin_port);
  ::close(fd);
  return port;
}

class Dispatch : public testing::Test {
 protected:
  // The tile (4 buildings) and its local batch.mk run, shared by both engines.
  static void SetUpTestSuite() {
    TileRun t = tile_and_batch("dispatch", 4);
    inputs_ = new fs::path(t.inputs);
    local_ = new std::map<std::string, std::string>(std::move(t.outputs));
    fs::remove_all(t.done);
  }
  static void TearDownTestSuite() { fs::remove_all(*inputs_); }

  static fs::path fresh_run(const std::string& name) {
    const fs::path run = fresh_dir(name);
    copy_run(*inputs_, run);
    return run;
  }

  // Every building has its outputs, identical to the local run, and the summary is written.
  static void expect_same_as_local(const fs::path& run) {
    const auto outputs = outcome_files(run);
    EXPECT_EQ(outputs.size(), local_->size());
    EXPECT_EQ(outputs, *local_);
    EXPECT_EQ(local_->size(), 8u) << "4 buildings, each refined.obj + report.json";
    const json summary = json::parse(read_text(run / "summary.json"));
    EXPECT_EQ(summary["pooled"]["buildings"], 4);
    EXPECT_TRUE(fs::exists(run / "report.html"));
    EXPECT_TRUE(temporaries(run).empty());
  }

  static fs::path* inputs_;
  static std::map<std::string, std::string>* local_;
};
fs::path* Dispatch::inputs_ = nullptr;
std::map<std::string, std::string>* Dispatch::local_ = nullptr;

TEST_F(Dispatch, GnuParallelOverSshLoginFileEqualsLocalBatch) {
  if (!installed("parallel")) GTEST_SKIP() << "GNU Parallel not installed (Debian: parallel)";
  const fs::path run = fresh_run("dispatch_parallel");
  const fs::path hosts = run.parent_path() / (run.filename().string() + "_hosts");
  std::ofstream(hosts) << "2/:\n";  // ":" is this machine (no ssh); other lines would be "N/user@host"
  const fs::path log = run.parent_path() / (run.filename().string() + ".log");
  ASSERT_EQ(shell("LODREFINE=" + shell_quoted(kBinary) + " HOME=" + shell_quoted(run.parent_path()) + " " +
                  shell_quoted(kSource / "scripts" / "parallel_batch.sh") + " " + shell_quoted(run) +
                  " --sshloginfile " + shell_quoted(hosts) + " > " + shell_quoted(log) + " 2>&1"),
            0)
      << read_text(log);
  expect_same_as_local(run);
  // A rerun has nothing left to do.
  ASSERT_EQ(shell("LODREFINE=" + shell_quoted(kBinary) + " HOME=" + shell_quoted(run.parent_path()) + " " +
                  shell_quoted(kSource / "scripts" / "parallel_batch.sh") + " " + shell_quoted(run) +
                  " --sshlogin : > " + shell_quoted(log) + " 2>&1"),
            0);
  EXPECT_NE(read_text(log).find("0 buildings to refine"), std::string::npos) << read_text(log);
  if (!HasFailure()) fs::remove_all(run), fs::remove(hosts), fs::remove(log);
}

// A lock let go a moment ago (a make run that just ended, whose holder is still on its way out) is
// waited for, not taken as another batch run: `make clean-results` then the dispatcher at once
// failed so on CI.
TEST_F(Dispatch, GnuParallelWaitsForALockJustLetGo) {
  if (!installed("parallel")) GTEST_SKIP() << "GNU Parallel not installed (Debian: parallel)";
  const fs::path run = fresh_run("dispatch_lock");
  const fs::path held = run.parent_path() / (run.filename().string() + "_held");
  const fs::path log = run.parent_path() / (run.filename().string() + ".log");
  ASSERT_EQ(shell("(exec 9>> " + shell_quoted(run / ".batch.lock") + "; flock 9; touch " + shell_quoted(held) +
                  "; sleep 0.4) & while [ ! -e " + shell_quoted(held) + " ]; do sleep 0.01; done; LODREFINE=" +
                  shell_quoted(kBinary) + " HOME=" + shell_quoted(run.parent_path()) + " " +
                  shell_quoted(kSource / "scripts" / "parallel_batch.sh") + " " + shell_quoted(run) +
                  " --sshlogin : > " + shell_quoted(log) + " 2>&1"),
            0)
      << read_text(log);
  expect_same_as_local(run);
  if (!HasFailure()) fs::remove_all(run), fs::remove(held), fs::remove(log);
}

TEST_F(Dispatch, SlurmJobArrayEqualsLocalBatch) {
  if (!installed("slurmctld slurmd munged mungekey sbatch sinfo squeue"))
    GTEST_SKIP() << "Slurm/munge not installed (Debian: slurm-wlm munge)";
  if (::geteuid() != 0) GTEST_SKIP() << "the one-node cluster (SlurmUser=root) needs root, as in CI";
  const fs::path cluster = fresh_dir("slurm_cluster");
  const std::string script = shell_quoted(kSource / "tests" / "slurm_one_node.sh");
  const std::string conf = "SLURM_CONF=" + shell_quoted(cluster / "etc" / "slurm.conf") + " ";
  const int ctld = free_port(), slurmd = free_port();
  ASSERT_TRUE(ctld > 0 && slurmd > 0 && ctld != slurmd);
  const int up = shell(script + " start " + shell_quoted(cluster) + " " + std::to_string(ctld) + " " +
                       std::to_string(slurmd) + " > /dev/null 2>&1");
  // Stop the daemons however the test ends (then their folder may go).
  struct Stop {
    std::string cmd;
    fs::path dir;
    bool remove = false;
    ~Stop() {
      shell(cmd);
      if (remove) fs::remove_all(dir);
    }
  } stop{conf + script + " stop " + shell_quoted(cluster) + " > /dev/null 2>&1", cluster};
  ASSERT_EQ(up, 0) << read_text(cluster / "log" / "slurmctld.log") << read_text(cluster / "log" / "slurmd.log");

  const fs::path run = fresh_run("dispatch_slurm");
  const fs::path log = run.parent_path() / (run.filename().string() + ".log");
  // MAX_TASKS=3: four buildings in three array tasks (one task does two), as a big tile would.
  ASSERT_EQ(shell(conf + "MAX_TASKS=3 LODREFINE=" + shell_quoted(kBinary) + " timeout 300 " +
                  shell_quoted(kSource / "scripts" / "slurm_batch.sh") + " " + shell_quoted(run) + " --wait > " +
                  shell_quoted(log) + " 2>&1"),
            0)
      << read_text(log);
  EXPECT_NE(read_text(log).find("4 buildings in 3 tasks"), std::string::npos) << read_text(log);
  expect_same_as_local(run);
  std::size_t task_logs = 0;
  for (const auto& e : fs::directory_iterator(run / ".slurm"))
    task_logs += e.path().filename().string().find('_') != std::string::npos;
  EXPECT_EQ(task_logs, 4u) << "3 array tasks + the summary job";
  if (!HasFailure()) fs::remove_all(run), fs::remove(log), stop.remove = true;
}

}  // namespace
