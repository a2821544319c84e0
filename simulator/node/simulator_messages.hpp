// Conversions between the simulator library's values and semx messages. The library knows no
// messages; the node knows no physics.
#pragma once

#include <semx/control_cmd_t.hpp>
#include <semx/depth_image_t.hpp>
#include <semx/imu_t.hpp>
#include <semx/label_image_t.hpp>
#include <semx/odometry_t.hpp>
#include <semx/rgb_image_t.hpp>

#include "semx/runtime/image_codec.hpp"
#include "semx/simulator/camera_frame.hpp"
#include "semx/simulator/quadrotor.hpp"
#include "semx/simulator/simulator.hpp"

namespace semx::simulator {

semx::odometry_t to_message(const OdometrySample& s);
semx::imu_t to_message(const ImuSample& s);
semx::camera_info_t camera_info(const CameraFrame& f);

// Images as little-endian bytes, encoded with the requested codec (runtime/image_codec.hpp;
// the codec actually used is in the message, raw when encoding would not shrink it). RGB comes
// from f.rgb_runs when the frame has runs and no image (kRenderRgbRuns), with the same payload.
semx::depth_image_t depth_message(const CameraFrame& f, runtime::ImageCompression codec);
semx::rgb_image_t rgb_message(const CameraFrame& f, runtime::ImageCompression codec);
semx::label_image_t label_message(const CameraFrame& f, runtime::ImageCompression codec);

// Fails (returns false) on values no vehicle command can mean: unknown modes, NaN or infinite
// numbers. Range limits are the quadrotor's business (it saturates or rejects).
bool well_formed(const semx::control_cmd_t& m);
ControlCommand from_message(const semx::control_cmd_t& m);

// Decodes an image payload back to raw bytes (for consumers and tests); false if the payload
// does not decode to exactly `expected_bytes`. Same as runtime::decode_image.
bool image_bytes(int8_t compression, const std::vector<uint8_t>& payload, std::size_t expected_bytes,
                 std::vector<uint8_t>& out);

}  // namespace semx::simulator
