// Who may talk on a set's bus: every semx message carries a trailer after its LCM payload that
// names the set (session), the sending process instance (sender), a counter and the message's
// sequence number on its channel, authenticated with the set's key (docs/runtime.md, "Who may
// talk"). One mechanism gives both set isolation (another session's messages are counted and
// dropped) and authentication (what is unsigned, forged, stale or replayed is dropped).
//
//   ... LCM payload ... | session u64 | sender u64 | counter u64 | seq u32 | tag[16] | "SXA1"
//
// The trailer comes after the bytes LCM's decoders read, so lcm-spy, lcm-logger, lcm-logplayer
// and liblcm's generated decoders (which ignore what follows a message) work unchanged.
//
// The tag is ChaCha20-Poly1305 (IETF) over the channel name, the payload and the trailer's fields,
// with no plaintext, under a key per sender derived from the set's key, and the counter as
// nonce: the derived key makes a nonce unique per (key, counter) whatever two senders draw. It was
// chosen by measured cost on 1 MB frames (`./semx perf runtime`, docs/runtime.md): about 6x
// cheaper than HMAC-SHA256 and 20x cheaper than keyed BLAKE2b here.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace semx::runtime {

inline constexpr std::size_t kAuthTrailerBytes = 48;
inline constexpr uint32_t kAuthMagic = 0x53584131;  // "SXA1"

// The set's key. Sets started by the launcher get a random one; `--auth-key FILE` (or
// SEMX_AUTH_KEY_FILE) shares one between the hosts of a multi-host set. A process given none runs
// in the open session: a fixed, public key, so processes started by hand and in-process tests talk
// to each other, but never to a keyed set.
class AuthKey {
 public:
  static AuthKey open();
  static AuthKey random();
  // 64 hex digits (a trailing newline allowed). Throws std::invalid_argument naming `what`.
  static AuthKey from_hex(const std::string& hex, const std::string& what);
  // The file must hold 64 hex digits; throws std::runtime_error naming the file.
  static AuthKey from_file(const std::string& path);
  // --auth-key FILE if given, else SEMX_AUTH_KEY (hex), else SEMX_AUTH_KEY_FILE, else open().
  static AuthKey resolve(const std::string& flag_file);

  std::string hex() const;
  // Writes hex() to `path`, readable by its owner only; refuses to replace an existing file.
  void write_file(const std::string& path) const;
  uint64_t session() const { return session_; }
  bool is_open() const { return open_; }
  const std::array<uint8_t, 32>& bytes() const { return key_; }
  // The key a sender's messages are tagged with.
  std::array<uint8_t, 32> sender_key(uint64_t sender) const;

 private:
  explicit AuthKey(const std::array<uint8_t, 32>& key, bool open);
  std::array<uint8_t, 32> key_{};
  uint64_t session_ = 0;
  bool open_ = false;
};

struct AuthTrailer {
  uint64_t session = 0;
  uint64_t sender = 0;
  uint64_t counter = 0;
  uint32_t seq = 0;  // 1, 2, ... per (sender, channel)
};

// The trailer of `data`, if its last bytes are one (magic and length only, nothing verified).
std::optional<AuthTrailer> read_trailer(const uint8_t* data, std::size_t size);
// `size` without a trailer, if there is one: what LCM's decoders should read.
std::size_t payload_size(const uint8_t* data, std::size_t size);

// Appends trailers. One per process instance: its sender id is random.
class MessageSigner {
 public:
  explicit MessageSigner(const AuthKey& key);
  ~MessageSigner();
  MessageSigner(const MessageSigner&) = delete;
  MessageSigner& operator=(const MessageSigner&) = delete;

  // Appends the trailer of the next message on `channel` to `bytes` (the payload).
  AuthTrailer sign(const std::string& channel, std::vector<uint8_t>& bytes);
  // Appends a trailer with a given seq (a message sent again: a new counter, its old seq).
  AuthTrailer sign_as(const std::string& channel, std::vector<uint8_t>& bytes, uint32_t seq);
  uint64_t sender() const { return sender_; }
  uint64_t session() const { return session_; }
  // The last seq given on `channel` (0 before any).
  uint32_t head(const std::string& channel) const;
  const std::map<std::string, uint32_t>& heads() const { return seq_; }

 private:
  struct Cipher;
  std::unique_ptr<Cipher> cipher_;
  uint64_t session_;
  uint64_t sender_;
  uint64_t counter_ = 0;
  std::map<std::string, uint32_t> seq_;
};

enum class AuthVerdict {
  kOk,
  kUnsigned,  // no trailer
  kForeign,   // another session's (another set on the same bus)
  kForged,    // the tag does not match: not made with this set's key, or altered
  kReplayed,  // a counter this sender used already, or older than the window
  kCrowded,   // a new sender when kMaxSenders are known already (a flood of insider senders)
};
const char* to_string(AuthVerdict v);

// Checks trailers. Replays are refused with a sliding window per sender, as IPsec and MAVLink 2
// signing do: a counter is accepted once, and only if it is within kWindow of the sender's
// highest, so a datagram reordered on the way still passes.
class MessageVerifier {
 public:
  explicit MessageVerifier(const AuthKey& key);
  ~MessageVerifier();
  MessageVerifier(const MessageVerifier&) = delete;
  MessageVerifier& operator=(const MessageVerifier&) = delete;

  static constexpr uint64_t kWindow = 64;
  // A set has a few dozen senders, respawns included: beyond this many, a new one is refused, so
  // a flood of senders with the key cannot grow this map (and each reader's inbox) without bound.
  static constexpr std::size_t kMaxSenders = 4096;

  AuthVerdict verify(const std::string& channel, const uint8_t* data, std::size_t size,
                     AuthTrailer* trailer = nullptr);
  // The tag alone, without the replay window: for a message verify() called replayed that the
  // reader still waits for (a publisher's resend carries the bytes it first sent, counter and
  // all, so readers can join its fragments with those of the first copy; delivery.hpp).
  bool authentic(const std::string& channel, const uint8_t* data, std::size_t size);
  uint64_t session() const { return session_; }
  std::size_t senders() const { return senders_.size(); }
  // A sender one of whose messages was verified.
  bool knows(uint64_t sender) const { return senders_.count(sender) > 0; }

 private:
  struct Cipher;
  struct Sender {
    std::array<uint8_t, 32> key;
    uint64_t highest = 0;
    uint64_t window = 0;  // bit i: highest - i was seen
    bool any = false;
  };
  std::unique_ptr<Cipher> cipher_;
  AuthKey key_;
  uint64_t session_;
  std::map<uint64_t, Sender> senders_;  // only senders with a verified message are kept
};

}  // namespace semx::runtime
