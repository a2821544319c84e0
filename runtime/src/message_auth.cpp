#include "semx/runtime/message_auth.hpp"

#include <fcntl.h>
#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <openssl/rand.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace semx::runtime {

namespace {

constexpr std::size_t kTagBytes = 16;
// Offsets from the trailer's start.
constexpr std::size_t kOffSession = 0, kOffSender = 8, kOffCounter = 16, kOffSeq = 24, kOffTag = 28,
                      kOffMagic = 44;
constexpr std::size_t kAuthenticated = kOffTag;  // the fields the tag covers

void put64(uint8_t* p, uint64_t v) {
  for (int i = 7; i >= 0; --i, v >>= 8) p[i] = static_cast<uint8_t>(v);
}
void put32(uint8_t* p, uint32_t v) {
  for (int i = 3; i >= 0; --i, v >>= 8) p[i] = static_cast<uint8_t>(v);
}
uint64_t get64(const uint8_t* p) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | p[i];
  return v;
}
uint32_t get32(const uint8_t* p) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v = (v << 8) | p[i];
  return v;
}

std::array<uint8_t, 32> hmac(const std::array<uint8_t, 32>& key, const std::string& label, uint64_t value) {
  uint8_t msg[64];
  const std::size_t n = std::min<std::size_t>(label.size(), 48);
  std::memcpy(msg, label.data(), n);
  put64(msg + n, value);
  std::array<uint8_t, 32> out{};
  unsigned int len = 0;
  if (!HMAC(EVP_sha256(), key.data(), static_cast<int>(key.size()), msg, n + 8, out.data(), &len) ||
      len != 32)
    throw std::runtime_error("HMAC-SHA256 failed");
  return out;
}

}  // namespace

// One EVP context, reused for every message: ChaCha20-Poly1305 with the payload as associated data.
struct Tagger {
  EVP_CIPHER_CTX* ctx = EVP_CIPHER_CTX_new();
  Tagger() {
    if (!ctx || EVP_EncryptInit_ex(ctx, EVP_chacha20_poly1305(), nullptr, nullptr, nullptr) != 1)
      throw std::runtime_error("OpenSSL: ChaCha20-Poly1305 is not available");
  }
  ~Tagger() { EVP_CIPHER_CTX_free(ctx); }
  Tagger(const Tagger&) = delete;
  Tagger& operator=(const Tagger&) = delete;

  // The tag of channel NUL payload trailer[0, kAuthenticated) under `key`, nonce = counter.
  bool tag(const std::array<uint8_t, 32>& key, const std::string& channel, const uint8_t* payload,
           std::size_t payload_size, const uint8_t* trailer, uint8_t out[kTagBytes]) {
    uint8_t nonce[12] = {0};
    std::memcpy(nonce + 4, trailer + kOffCounter, 8);
    int len = 0;
    if (EVP_EncryptInit_ex(ctx, nullptr, nullptr, key.data(), nonce) != 1) return false;
    const auto aad = [&](const uint8_t* p, std::size_t n) {
      // EVP's lengths are int: feed big payloads in pieces.
      while (n > 0) {
        const int k = static_cast<int>(std::min<std::size_t>(n, 1u << 30));
        if (EVP_EncryptUpdate(ctx, nullptr, &len, p, k) != 1) return false;
        p += k;
        n -= static_cast<std::size_t>(k);
      }
      return true;
    };
    if (!aad(reinterpret_cast<const uint8_t*>(channel.c_str()), channel.size() + 1)) return false;
    if (!aad(payload, payload_size) || !aad(trailer, kAuthenticated)) return false;
    uint8_t none[16];
    if (EVP_EncryptFinal_ex(ctx, none, &len) != 1) return false;
    return EVP_CIPHER_CTX_ctrl(ctx, EVP_CTRL_AEAD_GET_TAG, kTagBytes, out) == 1;
  }
};

struct MessageSigner::Cipher : Tagger {
  std::array<uint8_t, 32> key;
};
struct MessageVerifier::Cipher : Tagger {};

// ---- AuthKey ----

AuthKey::AuthKey(const std::array<uint8_t, 32>& key, bool open) : key_(key), open_(open) {
  const auto s = hmac(key_, "semx session", 0);
  session_ = get64(s.data());
}

AuthKey AuthKey::open() { return AuthKey(std::array<uint8_t, 32>{}, true); }

AuthKey AuthKey::random() {
  std::array<uint8_t, 32> k{};
  if (RAND_bytes(k.data(), static_cast<int>(k.size())) != 1)
    throw std::runtime_error("no random bytes for a key");
  return AuthKey(k, false);
}

AuthKey AuthKey::from_hex(const std::string& text, const std::string& what) {
  std::string hex = text;
  while (!hex.empty() && (hex.back() == '\n' || hex.back() == '\r' || hex.back() == ' ')) hex.pop_back();
  if (hex.size() != 64) {
    throw std::invalid_argument(what + ": a key is 64 hex digits (32 bytes), found " +
                                std::to_string(hex.size()) + " characters");
  }
  std::array<uint8_t, 32> k{};
  for (std::size_t i = 0; i < 32; ++i) {
    const auto digit = [&](char c) -> int {
      if (c >= '0' && c <= '9') return c - '0';
      if (c >= 'a' && c <= 'f') return c - 'a' + 10;
      if (c >= 'A' && c <= 'F') return c - 'A' + 10;
      throw std::invalid_argument(what + ": '" + std::string(1, c) + "' is not a hex digit");
    };
    k[i] = static_cast<uint8_t>(digit(hex[2 * i]) * 16 + digit(hex[2 * i + 1]));
  }
  return AuthKey(k, false);
}

AuthKey AuthKey::from_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read the key file: " + std::strerror(errno));
  std::stringstream ss;
  ss << in.rdbuf();
  try {
    return from_hex(ss.str(), path);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(e.what());
  }
}

AuthKey AuthKey::resolve(const std::string& flag_file) {
  if (!flag_file.empty()) return from_file(flag_file);
  if (const char* hex = std::getenv("SEMX_AUTH_KEY"); hex && *hex) {
    try {
      return from_hex(hex, "SEMX_AUTH_KEY");
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(e.what());
    }
  }
  if (const char* file = std::getenv("SEMX_AUTH_KEY_FILE"); file && *file) return from_file(file);
  return open();
}

std::string AuthKey::hex() const {
  static const char* d = "0123456789abcdef";
  std::string s;
  for (uint8_t b : key_) {
    s += d[b >> 4];
    s += d[b & 15];
  }
  return s;
}

void AuthKey::write_file(const std::string& path) const {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) throw std::runtime_error(path + ": cannot create the key file: " + std::strerror(errno));
  const std::string text = hex() + "\n";
  const bool ok = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  ::close(fd);
  if (!ok) throw std::runtime_error(path + ": cannot write the key file");
}

std::array<uint8_t, 32> AuthKey::sender_key(uint64_t sender) const {
  return hmac(key_, "semx sender", sender);
}

// ---- trailers ----

std::optional<AuthTrailer> read_trailer(const uint8_t* data, std::size_t size) {
  if (size < kAuthTrailerBytes) return std::nullopt;
  const uint8_t* t = data + size - kAuthTrailerBytes;
  if (get32(t + kOffMagic) != kAuthMagic) return std::nullopt;
  AuthTrailer a;
  a.session = get64(t + kOffSession);
  a.sender = get64(t + kOffSender);
  a.counter = get64(t + kOffCounter);
  a.seq = get32(t + kOffSeq);
  return a;
}

std::size_t payload_size(const uint8_t* data, std::size_t size) {
  return read_trailer(data, size) ? size - kAuthTrailerBytes : size;
}

const char* to_string(AuthVerdict v) {
  switch (v) {
    case AuthVerdict::kOk:
      return "ok";
    case AuthVerdict::kUnsigned:
      return "unsigned";
    case AuthVerdict::kForeign:
      return "another set's";
    case AuthVerdict::kForged:
      return "forged";
    case AuthVerdict::kReplayed:
      return "replayed";
    case AuthVerdict::kCrowded:
      return "surplus sender's";
  }
  return "?";
}

// ---- MessageSigner ----

MessageSigner::MessageSigner(const AuthKey& key)
    : cipher_(std::make_unique<Cipher>()), session_(key.session()) {
  uint8_t id[8];
  if (RAND_bytes(id, sizeof id) != 1) throw std::runtime_error("no random bytes for a sender id");
  sender_ = get64(id);
  cipher_->key = key.sender_key(sender_);
}

MessageSigner::~MessageSigner() = default;

AuthTrailer MessageSigner::sign(const std::string& channel, std::vector<uint8_t>& bytes) {
  return sign_as(channel, bytes, ++seq_[channel]);
}

AuthTrailer MessageSigner::sign_as(const std::string& channel, std::vector<uint8_t>& bytes, uint32_t seq) {
  AuthTrailer a;
  a.session = session_;
  a.sender = sender_;
  a.counter = ++counter_;
  a.seq = seq;
  const std::size_t payload = bytes.size();
  bytes.resize(payload + kAuthTrailerBytes);
  uint8_t* t = bytes.data() + payload;
  put64(t + kOffSession, a.session);
  put64(t + kOffSender, a.sender);
  put64(t + kOffCounter, a.counter);
  put32(t + kOffSeq, a.seq);
  put32(t + kOffMagic, kAuthMagic);
  if (!cipher_->tag(cipher_->key, channel, bytes.data(), payload, t, t + kOffTag))
    throw std::runtime_error("OpenSSL: tagging a message failed");
  return a;
}

uint32_t MessageSigner::head(const std::string& channel) const {
  const auto it = seq_.find(channel);
  return it == seq_.end() ? 0 : it->second;
}

// ---- MessageVerifier ----

MessageVerifier::MessageVerifier(const AuthKey& key)
    : cipher_(std::make_unique<Cipher>()), key_(key), session_(key.session()) {}

MessageVerifier::~MessageVerifier() = default;

AuthVerdict MessageVerifier::verify(const std::string& channel, const uint8_t* data, std::size_t size,
                                    AuthTrailer* trailer) {
  const auto a = read_trailer(data, size);
  if (!a) return AuthVerdict::kUnsigned;
  if (trailer) *trailer = *a;
  if (a->session != session_) return AuthVerdict::kForeign;
  const auto it = senders_.find(a->sender);
  if (it == senders_.end() && senders_.size() >= kMaxSenders) return AuthVerdict::kCrowded;
  Sender fresh;
  Sender& s = it != senders_.end() ? it->second : fresh;
  if (it == senders_.end()) fresh.key = key_.sender_key(a->sender);
  // Replays are refused before the tag is computed: cheap, and a replay is well formed anyway.
  if (s.any) {
    if (a->counter + kWindow <= s.highest) return AuthVerdict::kReplayed;
    if (a->counter <= s.highest && (s.window >> (s.highest - a->counter)) & 1u) return AuthVerdict::kReplayed;
  }
  const std::size_t payload = size - kAuthTrailerBytes;
  const uint8_t* t = data + payload;
  uint8_t tag[kTagBytes];
  if (!cipher_->tag(s.key, channel, data, payload, t, tag) || CRYPTO_memcmp(tag, t + kOffTag, kTagBytes) != 0)
    return AuthVerdict::kForged;
  if (!s.any || a->counter > s.highest) {
    const uint64_t shift = s.any ? a->counter - s.highest : kWindow;
    s.window = shift >= kWindow ? 0 : s.window << shift;
    s.window |= 1u;
    s.highest = a->counter;
  } else {
    s.window |= uint64_t{1} << (s.highest - a->counter);
  }
  s.any = true;
  if (it == senders_.end()) senders_.emplace(a->sender, fresh);
  return AuthVerdict::kOk;
}

bool MessageVerifier::authentic(const std::string& channel, const uint8_t* data, std::size_t size) {
  const auto a = read_trailer(data, size);
  if (!a || a->session != session_) return false;
  const auto it = senders_.find(a->sender);
  const std::array<uint8_t, 32> key = it != senders_.end() ? it->second.key : key_.sender_key(a->sender);
  const std::size_t payload = size - kAuthTrailerBytes;
  const uint8_t* t = data + payload;
  uint8_t tag[kTagBytes];
  return cipher_->tag(key, channel, data, payload, t, tag) && CRYPTO_memcmp(tag, t + kOffTag, kTagBytes) == 0;
}

}  // namespace semx::runtime
