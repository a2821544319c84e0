// semx-perf-runtime: what the node runtime costs per message. One 'name: value unit' line per
// figure (./semx perf runtime).
#include <semx/depth_image_t.hpp>
#include <semx/odometry_t.hpp>

#include <openssl/evp.h>
#include <openssl/hmac.h>
#ifdef SEMX_PERF_SODIUM
#include <sodium.h>
#endif

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>

#include "semx/runtime/args.hpp"
#include "semx/runtime/node.hpp"
#include "semx/runtime/wire_generator.hpp"

using namespace semx::runtime;
using Clock = std::chrono::steady_clock;

namespace {

template <class F>
double per_second(int n, F&& f) {
  const auto t0 = Clock::now();
  for (int i = 0; i < n; ++i) f(i);
  return n / std::chrono::duration<double>(Clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
  return run_main("semx-perf-runtime", [&] {
    int reps = 2000;
    ArgParser p("semx-perf-runtime", "Benchmarks message validation, decoding and in-process delivery.");
    p.option("reps", "N", "repetitions per figure (default 2000)", &reps);
    if (!p.parse(argc, argv)) return 0;

    const auto& schema = LcmSchema::semx();
    semx::depth_image_t frame{};
    frame.info.width = 640;
    frame.info.height = 480;
    frame.num_depth_bytes = 640 * 480 * 2;
    frame.depth_data.assign(static_cast<std::size_t>(frame.num_depth_bytes), 7);
    std::vector<uint8_t> bytes(static_cast<std::size_t>(frame.getEncodedSize()));
    frame.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    const auto& depth_type = *schema.find("semx.depth_image_t");
    volatile int sink = 0;

    const double validate = per_second(reps, [&](int) {
      sink = sink + static_cast<int>(validate_wire(schema, depth_type, semx::depth_image_t::getHash(),
                                                   bytes.data(), bytes.size()));
    });
    const double decode = per_second(reps / 4, [&](int) {
      semx::depth_image_t m;
      sink = sink + m.decode(bytes.data(), 0, static_cast<int>(bytes.size()));
    });
    std::printf("validate_depth_frame_640x480: %.0f frames/s\n", validate);
    std::printf("decode_depth_frame_640x480: %.0f frames/s\n", decode);
    std::printf("validation_overhead_vs_decode: %.2f %%\n", 100.0 * decode / validate);

    std::mt19937_64 rng(1);
    const auto& path_type = *schema.find("semx.roadmap_t");
    std::vector<std::vector<uint8_t>> hostile;
    for (int i = 0; i < 1000; ++i) {
      hostile.push_back(hostile_wire_message(schema, path_type, all_hostile_kinds()[i % 7], rng));
    }
    const double reject = per_second(reps * 10, [&](int i) {
      const auto& h = hostile[static_cast<std::size_t>(i) % hostile.size()];
      sink = sink + static_cast<int>(
                        validate_wire(schema, path_type, schema.fingerprint(path_type), h.data(), h.size()));
    });
    std::printf("hostile_roadmap_checks: %.0f messages/s\n", reject);

    NodeOptions o;
    o.name = "perf";
    o.lcm_url = "memq://";
    o.quiet = true;
    o.status_period_s = 1e6;
    Node node(o);
    int64_t received = 0;
    node.subscribe<semx::odometry_t>("ODOMETRY", [&](const semx::odometry_t&) { ++received; });
    semx::odometry_t od{};
    const double roundtrip = per_second(reps * 10, [&](int) {
      node.publish("ODOMETRY", od);
      node.drain();
    });
    std::printf("memq_publish_validate_decode_deliver_odometry: %.0f messages/s\n", roundtrip);

    // The message tag on a 1 MB camera frame (message_auth.hpp): the one semx uses, then the
    // candidates it was chosen from, all from Debian's libraries (ms per MB: lower is better).
    const std::size_t mb = 1u << 20;
    std::vector<uint8_t> big(mb, 7), signed_frame;
    const AuthKey key = AuthKey::random();
    MessageSigner signer(key);
    MessageVerifier verifier(key);
    const int macs = std::max(20, reps / 20);
    auto ms_per_mb = [&](auto&& f) { return 1e3 / per_second(macs, f); };
    const double sign = ms_per_mb([&](int) {
      signed_frame.assign(big.begin(), big.end());
      signer.sign("CAMERA_DEPTH", signed_frame);
    });
    int ok = 0;
    const double verify = ms_per_mb([&](int) {
      // A new verifier each time: the same message twice is a replay.
      MessageVerifier v(key);
      ok += v.verify("CAMERA_DEPTH", signed_frame.data(), signed_frame.size()) == AuthVerdict::kOk;
    });
    std::printf("auth_sign_1MB_chacha20_poly1305: %.3f ms\n", sign);
    std::printf("auth_verify_1MB_chacha20_poly1305: %.3f ms\n", verify);
    uint8_t out[64];
    unsigned int len = 0;
    const auto& k = key.bytes();
    std::printf("auth_candidate_hmac_sha256_1MB: %.3f ms\n", ms_per_mb([&](int) {
                  HMAC(EVP_sha256(), k.data(), 32, big.data(), big.size(), out, &len);
                }));
    EVP_CIPHER_CTX* ctx = EVP_CIPHER_CTX_new();
    auto aead = [&](const EVP_CIPHER* cipher, int get_tag) {
      return ms_per_mb([&](int i) {
        uint8_t nonce[12] = {static_cast<uint8_t>(i)};
        int n = 0;
        EVP_EncryptInit_ex(ctx, cipher, nullptr, k.data(), nonce);
        EVP_EncryptUpdate(ctx, nullptr, &n, big.data(), static_cast<int>(big.size()));
        EVP_EncryptFinal_ex(ctx, out, &n);
        EVP_CIPHER_CTX_ctrl(ctx, get_tag, 16, out);
      });
    };
    std::printf("auth_candidate_aes256_gcm_gmac_1MB: %.3f ms\n", aead(EVP_aes_256_gcm(), EVP_CTRL_GCM_GET_TAG));
    std::printf("auth_candidate_chacha20_poly1305_1MB: %.3f ms\n",
                aead(EVP_chacha20_poly1305(), EVP_CTRL_AEAD_GET_TAG));
    EVP_CIPHER_CTX_free(ctx);
#ifdef SEMX_PERF_SODIUM
    if (sodium_init() >= 0) {
      std::printf("auth_candidate_sodium_blake2b_keyed_1MB: %.3f ms\n", ms_per_mb([&](int) {
                    crypto_generichash(out, 32, big.data(), big.size(), k.data(), 32);
                  }));
      std::printf("auth_candidate_sodium_hmac_sha256_1MB: %.3f ms\n", ms_per_mb([&](int) {
                    crypto_auth_hmacsha256(out, big.data(), big.size(), k.data());
                  }));
    }
#endif
    return received == reps * 10 && ok == macs ? 0 : 1;
  });
}
