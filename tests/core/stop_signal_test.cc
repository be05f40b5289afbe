// The stop request of SIGINT / SIGTERM (core/stop_signal.h): the first signal is recorded and the
// process goes on; a second one takes the default action (terminates).
#include "core/stop_signal.h"

#include <gtest/gtest.h>

#include <csignal>

#include <sys/wait.h>
#include <unistd.h>

namespace exotwin {
namespace {

// Runs `body` in a forked child (the handlers change the process's dispositions) and returns its
// wait status.
template <class F>
int InChild(F body) {
  const pid_t pid = fork();
  if (pid == 0) _exit(body());
  int status = 0;
  waitpid(pid, &status, 0);
  return status;
}

TEST(StopSignal, NoneBeforeASignal) {
  ResetStopSignal();
  EXPECT_EQ(StopSignal(), 0);
}

TEST(StopSignal, FirstSignalIsRecordedNotFatal) {
  for (int sig : {SIGINT, SIGTERM}) {
    const int status = InChild([sig] {
      InstallStopSignalHandlers();
      if (StopSignal() != 0) return 10;
      raise(sig);
      if (StopSignal() != sig) return 11;
      ResetStopSignal();
      return StopSignal() == 0 ? 0 : 12;
    });
    ASSERT_TRUE(WIFEXITED(status)) << "signal " << sig;
    EXPECT_EQ(WEXITSTATUS(status), 0) << "signal " << sig;
  }
}

TEST(StopSignal, SecondSignalTakesTheDefaultAction) {
  const int status = InChild([] {
    InstallStopSignalHandlers();
    raise(SIGINT);
    raise(SIGTERM);  // the default action of SIGTERM: terminate
    return 0;
  });
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), SIGTERM);
}

TEST(StopSignal, Names) {
  EXPECT_STREQ(StopSignalName(SIGINT), "SIGINT");
  EXPECT_STREQ(StopSignalName(SIGTERM), "SIGTERM");
  EXPECT_STREQ(StopSignalName(SIGHUP), "signal");
}

}  // namespace
}  // namespace exotwin
