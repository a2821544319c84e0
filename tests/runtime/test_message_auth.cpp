// The trailer every semx message carries (message_auth.hpp): what one set signs, another set, a
// process without the key, a tamperer or a replayer cannot get accepted.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "semx/runtime/message_auth.hpp"

using namespace semx::runtime;

namespace {

std::vector<uint8_t> payload(std::size_t n, uint8_t fill = 7) { return std::vector<uint8_t>(n, fill); }

// `n` messages of one sender on `channel`, signed in order (counters 1..n).
std::vector<std::vector<uint8_t>> signed_series(MessageSigner& signer, const std::string& channel, int n) {
  std::vector<std::vector<uint8_t>> sent;
  for (int i = 0; i < n; ++i) {
    auto b = payload(20, static_cast<uint8_t>(i));
    signer.sign(channel, b);
    sent.push_back(b);
  }
  return sent;
}

}  // namespace

TEST(MessageAuth, WhatASetSignsItsReadersAccept) {
  const AuthKey key = AuthKey::random();
  MessageSigner signer(key);
  MessageVerifier verifier(key);
  auto bytes = payload(1000);
  const AuthTrailer t = signer.sign("ODOMETRY", bytes);
  ASSERT_EQ(bytes.size(), 1000 + kAuthTrailerBytes);
  EXPECT_EQ(payload_size(bytes.data(), bytes.size()), 1000u);
  AuthTrailer read;
  EXPECT_EQ(verifier.verify("ODOMETRY", bytes.data(), bytes.size(), &read), AuthVerdict::kOk);
  EXPECT_EQ(read.session, key.session());
  EXPECT_EQ(read.sender, signer.sender());
  EXPECT_EQ(read.seq, 1u);
  EXPECT_EQ(t.counter, read.counter);
  // Sequence numbers count per channel, counters per sender.
  auto b2 = payload(10), b3 = payload(10);
  EXPECT_EQ(signer.sign("ODOMETRY", b2).seq, 2u);
  const AuthTrailer t3 = signer.sign("PLAN_PATH", b3);
  EXPECT_EQ(t3.seq, 1u);
  EXPECT_EQ(t3.counter, 3u);
  EXPECT_EQ(verifier.verify("PLAN_PATH", b3.data(), b3.size()), AuthVerdict::kOk);
}

TEST(MessageAuth, AnotherSetsMessagesAreForeign) {
  const AuthKey a = AuthKey::random(), b = AuthKey::random();
  ASSERT_NE(a.session(), b.session());
  MessageSigner other(b);
  MessageVerifier mine(a);
  auto bytes = payload(64);
  other.sign("SIM_CLOCK", bytes);
  EXPECT_EQ(mine.verify("SIM_CLOCK", bytes.data(), bytes.size()), AuthVerdict::kForeign);
  // The open session (no key) is a set of its own too.
  MessageSigner open(AuthKey::open());
  auto o = payload(64);
  open.sign("SIM_CLOCK", o);
  EXPECT_EQ(mine.verify("SIM_CLOCK", o.data(), o.size()), AuthVerdict::kForeign);
}

TEST(MessageAuth, UnsignedTamperedAndWrongKeyedMessagesAreRefused) {
  const AuthKey key = AuthKey::random();
  MessageSigner signer(key);
  MessageVerifier verifier(key);
  auto plain = payload(100);
  EXPECT_EQ(verifier.verify("PLAN_PATH", plain.data(), plain.size()), AuthVerdict::kUnsigned);
  auto bytes = payload(100);
  signer.sign("PLAN_PATH", bytes);
  for (std::size_t at :
       {std::size_t{0}, std::size_t{50}, std::size_t{99}, std::size_t{100 + 20}, std::size_t{100 + 30}}) {
    auto t = bytes;
    t[at] ^= 0x01;
    EXPECT_EQ(verifier.verify("PLAN_PATH", t.data(), t.size()), AuthVerdict::kForged) << "byte " << at;
  }
  // The channel is covered too: a message cannot be moved to another channel.
  EXPECT_EQ(verifier.verify("TRAJECTORY", bytes.data(), bytes.size()), AuthVerdict::kForged);
  // A forger who knows the session id (it is on the wire) but not the key: same session, bad tag.
  const AuthKey guess = AuthKey::random();
  MessageSigner forger(guess);
  auto f = payload(100);
  forger.sign("PLAN_PATH", f);
  std::copy(bytes.end() - kAuthTrailerBytes, bytes.end() - kAuthTrailerBytes + 8,
            f.end() - kAuthTrailerBytes);
  EXPECT_EQ(verifier.verify("PLAN_PATH", f.data(), f.size()), AuthVerdict::kForged);
  EXPECT_EQ(verifier.verify("PLAN_PATH", bytes.data(), bytes.size()), AuthVerdict::kOk);
}

TEST(MessageAuth, ReplaysAreRefusedReorderingWithinTheWindowIsNot) {
  const AuthKey key = AuthKey::random();
  MessageSigner signer(key);
  MessageVerifier verifier(key);
  const auto sent = signed_series(signer, "ODOMETRY", 100);
  EXPECT_EQ(verifier.verify("ODOMETRY", sent[10].data(), sent[10].size()), AuthVerdict::kOk);
  EXPECT_EQ(verifier.verify("ODOMETRY", sent[10].data(), sent[10].size()), AuthVerdict::kReplayed);
  EXPECT_EQ(verifier.verify("ODOMETRY", sent[5].data(), sent[5].size()), AuthVerdict::kOk);  // late, not seen
  EXPECT_EQ(verifier.verify("ODOMETRY", sent[5].data(), sent[5].size()), AuthVerdict::kReplayed);
  EXPECT_EQ(verifier.verify("ODOMETRY", sent[99].data(), sent[99].size()), AuthVerdict::kOk);
  // Older than the window: stale.
  EXPECT_EQ(verifier.verify("ODOMETRY", sent[20].data(), sent[20].size()), AuthVerdict::kReplayed);
  EXPECT_EQ(verifier.verify("ODOMETRY", sent[98].data(), sent[98].size()), AuthVerdict::kOk);
}

TEST(MessageAuth, AResendAwaitedIsAuthenticBeyondTheWindowAndAForgedOneIsNot) {
  // A publisher resends the bytes it first sent, counter and all: past the window the verifier
  // calls it replayed, and the node asks authentic() when its inbox still waits for it.
  const AuthKey key = AuthKey::random();
  MessageSigner signer(key);
  MessageVerifier verifier(key);
  const auto sent = signed_series(signer, "ESDF_LOCAL", 100);
  EXPECT_EQ(verifier.verify("ESDF_LOCAL", sent[99].data(), sent[99].size()), AuthVerdict::kOk);
  EXPECT_EQ(verifier.verify("ESDF_LOCAL", sent[3].data(), sent[3].size()), AuthVerdict::kReplayed);
  EXPECT_TRUE(verifier.authentic("ESDF_LOCAL", sent[3].data(), sent[3].size()));
  EXPECT_FALSE(verifier.authentic("PLAN_PATH", sent[3].data(), sent[3].size())) << "another channel's";
  auto tampered = sent[3];
  tampered[2] ^= 1;
  EXPECT_FALSE(verifier.authentic("ESDF_LOCAL", tampered.data(), tampered.size()));
  const AuthKey other = AuthKey::random();
  MessageSigner stranger(other);
  auto foreign = payload(20);
  stranger.sign("ESDF_LOCAL", foreign);
  EXPECT_FALSE(verifier.authentic("ESDF_LOCAL", foreign.data(), foreign.size()));
}

TEST(MessageAuth, NewSendersBeyondTheLimitAreRefusedKnownOnesAreNot) {
  const AuthKey key = AuthKey::random();
  MessageVerifier verifier(key);
  MessageSigner first(key);
  auto b = payload(8);
  first.sign("ODOMETRY", b);
  ASSERT_EQ(verifier.verify("ODOMETRY", b.data(), b.size()), AuthVerdict::kOk);
  for (std::size_t i = 1; i < MessageVerifier::kMaxSenders; ++i) {
    MessageSigner s(key);
    auto m = payload(8);
    s.sign("ODOMETRY", m);
    ASSERT_EQ(verifier.verify("ODOMETRY", m.data(), m.size()), AuthVerdict::kOk) << i;
  }
  EXPECT_EQ(verifier.senders(), MessageVerifier::kMaxSenders);
  MessageSigner late(key);
  auto m = payload(8);
  late.sign("ODOMETRY", m);
  EXPECT_EQ(verifier.verify("ODOMETRY", m.data(), m.size()), AuthVerdict::kCrowded);
  EXPECT_EQ(verifier.senders(), MessageVerifier::kMaxSenders);
  auto again = payload(8);
  first.sign("ODOMETRY", again);
  EXPECT_EQ(verifier.verify("ODOMETRY", again.data(), again.size()), AuthVerdict::kOk);
}

TEST(MessageAuth, KeysFromHexFilesAndTheEnvironment) {
  const AuthKey key = AuthKey::random();
  const std::string dir = testing::TempDir() + "/semx_auth_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  const std::string file = dir + "/session.key";
  std::filesystem::remove(file);
  key.write_file(file);
  EXPECT_EQ(std::filesystem::status(file).permissions() & std::filesystem::perms::all,
            std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
  EXPECT_THROW(key.write_file(file), std::runtime_error);  // never replaced
  EXPECT_EQ(AuthKey::from_file(file).session(), key.session());
  EXPECT_EQ(AuthKey::resolve(file).session(), key.session());
  std::ofstream(dir + "/bad.key") << "12345\n";
  try {
    AuthKey::from_file(dir + "/bad.key");
    FAIL() << "a short key was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.key"), std::string::npos) << e.what();
  }
  EXPECT_THROW(AuthKey::from_hex(std::string(64, 'g'), "x"), std::invalid_argument);
  setenv("SEMX_AUTH_KEY", key.hex().c_str(), 1);
  EXPECT_EQ(AuthKey::resolve("").session(), key.session());
  unsetenv("SEMX_AUTH_KEY");
  EXPECT_TRUE(AuthKey::resolve("").is_open());
  std::filesystem::remove_all(dir);
}
