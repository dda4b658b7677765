// ProcessSample reads what the soak judges: each figure must move when the process changes.
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstring>
#include <memory>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "tests/soak/process_sample.hpp"

namespace facet::soak {
namespace {

TEST(ProcessSample, CountsOpenedFiles) {
  const auto before = sampleProcess(::getpid());
  ASSERT_TRUE(before);
  std::vector<int> fds;
  for (int i = 0; i < 5; ++i) fds.push_back(::open("/dev/null", O_RDONLY | O_CLOEXEC));
  const auto during = sampleProcess(::getpid());
  for (int fd : fds) ::close(fd);
  ASSERT_TRUE(during);
  EXPECT_EQ(during->fds - before->fds, 5);
}

TEST(ProcessSample, CountsThreads) {
  const auto before = sampleProcess(::getpid());
  ASSERT_TRUE(before);
  std::atomic<bool> stop{false};
  std::thread worker([&] {
    while (!stop) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  });
  const auto during = sampleProcess(::getpid());
  stop = true;
  worker.join();
  ASSERT_TRUE(during);
  EXPECT_EQ(during->threads - before->threads, 1);
}

TEST(ProcessSample, SeesResidentMemoryGrowWhenPagesAreTouched) {
  const auto before = sampleProcess(::getpid());
  ASSERT_TRUE(before);
  constexpr std::size_t kBytes = 64 << 20;
  auto block = std::make_unique<char[]>(kBytes);
  std::memset(block.get(), 1, kBytes);  // allocated is not resident: touch every page
  const auto during = sampleProcess(::getpid());
  ASSERT_TRUE(during);
  EXPECT_GT(during->rssMiB - before->rssMiB, 60.0);
  EXPECT_EQ(block[kBytes - 1], 1);
}

TEST(ProcessSample, EndedProcessHasNoSample) {
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) ::_exit(0);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  EXPECT_FALSE(sampleProcess(child));
}

}  // namespace
}  // namespace facet::soak
