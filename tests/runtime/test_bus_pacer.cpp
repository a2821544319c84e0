// Pacing a sender for readers that hold little (bus_pacer.hpp): what may go at once, what waits,
// and the sender that sleeps those waits.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <vector>

#include "semx/runtime/bus_pacer.hpp"
#include "semx/runtime/lcm_url.hpp"
#include "semx/runtime/udpm_sender.hpp"

using namespace semx::runtime;

TEST(BusPacer, ParsesThePaceAndRefusesWhatIsNot) {
  auto p = parse_bus_pace("40");
  ASSERT_TRUE(p);
  EXPECT_DOUBLE_EQ(p->bytes_per_s, 40e6);
  EXPECT_DOUBLE_EQ(p->burst_bytes, 200e3);
  EXPECT_DOUBLE_EQ(p->datagram_bytes, 0);
  p = parse_bus_pace("2.5:100:1");
  ASSERT_TRUE(p);
  EXPECT_DOUBLE_EQ(p->bytes_per_s, 2.5e6);
  EXPECT_DOUBLE_EQ(p->burst_bytes, 100e3);
  EXPECT_DOUBLE_EQ(p->datagram_bytes, 1e3);
  // A burst below one datagram would hold every fragment forever: raised to one.
  EXPECT_DOUBLE_EQ(parse_bus_pace("1:1")->burst_bytes, 65536);
  EXPECT_FALSE(BusPacer(*parse_bus_pace("0")).active());
  EXPECT_FALSE(BusPacer(*parse_bus_pace("")).active());
  for (const char* bad : {"x", "-1", "1:", ":1", "1::2", "1:2:3:4", "1e9", "nan", "4 0"})
    EXPECT_FALSE(parse_bus_pace(bad)) << bad;
}

TEST(BusPacer, NoWindowCarriesMoreThanTheBurstAndTheRate) {
  BusPace pace{10e6, 200e3, 0};
  BusPacer pacer(pace);
  // 40 fragments of 64 KB (a 2.6 MB message) sent as the pacer says, from t = 5 s.
  double t = 5.0;
  std::vector<double> sent;
  for (int k = 0; k < 40; ++k) {
    t += pacer.delay(64000, t);
    sent.push_back(t);
  }
  // The first three fit the burst and go at once; the last one waits for the rest at 10 MB/s.
  EXPECT_DOUBLE_EQ(sent[2], 5.0);
  EXPECT_GT(sent[3], 5.0);
  EXPECT_NEAR(sent.back() - 5.0, (40 * 64000 - 200e3) / 10e6, 1e-9);
  for (std::size_t i = 0; i < sent.size(); ++i)
    for (std::size_t j = i; j < sent.size(); ++j)
      EXPECT_LE((j - i + 1) * 64000.0, pace.burst_bytes + (sent[j] - sent[i]) * pace.bytes_per_s + 1e-3);
  // Quiet time fills the bucket again, up to the burst and no further.
  EXPECT_EQ(pacer.delay(150000, t + 10.0), 0.0);
  EXPECT_GT(pacer.delay(64000, t + 10.0), 0.0);
}

TEST(BusPacer, ADatagramCostsAtLeastItsFloor) {
  BusPacer pacer(BusPace{1e6, 65536, 10e3});  // 100 small datagrams a second after the burst
  double t = 0;
  int at_once = 0;
  while (pacer.delay(100, t) == 0.0) ++at_once;
  EXPECT_EQ(at_once, 6);  // 65 536 / 10 000
}

TEST(BusPacer, TheSenderWaitsItsTurn) {
  // A port of its own, next to test_udpm.cpp's (offsets 0-8 of 40000 + 10 per pid).
  const auto endpoint =
      parse_udpm_url(udpm_url_for_port(40000 + (static_cast<int>(getpid()) % 2000) * 10 + 9));
  ASSERT_TRUE(endpoint);
  std::vector<uint8_t> frame(1'000'000, 7);
  // 0.5 MB beyond the burst at 5 MB/s: 0.1 s at least, however fast the machine.
  UdpmSender paced(*endpoint, BusPace{5e6, 500e3, 0});
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE(paced.publish("PACED", frame.data(), frame.size()));
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_GE(took, 0.095);
}
