// State files (state_file.hpp): what a process finds after it was killed at any instant.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "semx/runtime/restart_count.hpp"
#include "semx/runtime/state_file.hpp"

using namespace semx::runtime;
namespace fs = std::filesystem;

namespace {

constexpr uint32_t kKind = state_kind("TEST");

std::string temp(const std::string& name) {
  const std::string p = ::testing::TempDir() + "/state_" + std::to_string(getpid()) + "_" + name;
  fs::remove(p);
  return p;
}

std::vector<uint8_t> bytes(std::size_t n, uint8_t v) { return std::vector<uint8_t>(n, v); }

}  // namespace

TEST(StateFile, SlotHoldsTheLastRecordWrittenInPlace) {
  const std::string path = temp("slot");
  EXPECT_FALSE(read_state_slot(path, kKind)) << "no file: nothing saved";
  {
    StateSlot slot(path, kKind);
    slot.write(bytes(100, 1));
    slot.write(bytes(10, 2));  // shorter than the first: the old tail must not be read
    EXPECT_EQ(*read_state_slot(path, kKind), bytes(10, 2));
  }
  EXPECT_THROW(read_state_slot(path, state_kind("OTHR")), StateFileError) << "another kind of file";
  // A damaged payload is refused, never half-read.
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(14);
    f.put(7);
  }
  EXPECT_THROW(read_state_slot(path, kKind), StateFileError);
  // Opening a slot starts it afresh.
  StateSlot again(path, kKind);
  EXPECT_FALSE(read_state_slot(path, kKind));
}

TEST(StateFile, JournalReadsUpToARecordCutShort) {
  const std::string path = temp("journal");
  EXPECT_TRUE(read_state_journal(path, kKind).empty());
  {
    StateJournal j(path, kKind, true);
    j.append(bytes(5, 1));
    j.append(bytes(0, 0));
    j.append(bytes(300, 3));
  }
  uint64_t valid = 0;
  auto records = read_state_journal(path, kKind, &valid);
  ASSERT_EQ(records.size(), 3u);
  EXPECT_EQ(records[0], bytes(5, 1));
  EXPECT_TRUE(records[1].empty());
  EXPECT_EQ(records[2], bytes(300, 3));
  EXPECT_EQ(valid, fs::file_size(path));
  // Killed in the middle of the third record's write: the first two are what is left.
  fs::resize_file(path, fs::file_size(path) - 100);
  records = read_state_journal(path, kKind, &valid);
  EXPECT_EQ(records.size(), 2u);
  EXPECT_EQ(valid, 12u + 5u + 12u);
  {
    // Reopened without truncating, cut to the whole records and appended to: read in order.
    StateJournal j(path, kKind, false);
    j.truncate(valid);
    j.append(bytes(7, 9));
  }
  records = read_state_journal(path, kKind);
  ASSERT_EQ(records.size(), 3u);
  EXPECT_EQ(records[2], bytes(7, 9));
  {
    StateJournal j(path, kKind, false);
    j.clear();
  }
  EXPECT_TRUE(read_state_journal(path, kKind).empty());
  std::ofstream(path) << "not a journal at all, but long enough";
  EXPECT_THROW(read_state_journal(path, kKind), StateFileError);
}

TEST(StateFile, RestartCountComesFromTheLauncher) {
  unsetenv(kRestartEnv);
  EXPECT_EQ(restart_count(), 0);
  setenv(kRestartEnv, "3", 1);
  EXPECT_EQ(restart_count(), 3);
  for (const char* bad : {"-1", "x", "2x", ""}) {
    setenv(kRestartEnv, bad, 1);
    EXPECT_EQ(restart_count(), 0) << bad;
  }
  unsetenv(kRestartEnv);
}
