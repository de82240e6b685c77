// dds::safe_deserialize_payload: what every craneassist reader does with the bytes of a sample,
// without DDS. Well-formed payloads of every topic pass; malformed ones (a bool byte of 2, a bad
// encapsulation, a cut-off body, a sequence over its bound) are rejected, and no input of any
// size or content throws or crashes (random mutations of well-formed payloads).
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "craneassist/dds/payload_check.hpp"
#include "dds_raw_writer.hpp"

namespace craneassist {
namespace {

using dds::Topic;

constexpr Topic kAll[] = {Topic::kStatus, Topic::kJoints, Topic::kHydraulics, Topic::kCommandPath,
                          Topic::kOperatorCommand};

test::Payload valid_payload(Topic topic) {
  return topic == Topic::kOperatorCommand
             ? test::operator_command_payload(7, "operator@console", {0.1, -0.2, 0.3}, true)
             : test::telemetry_payload(topic, 42);
}

bool check(Topic topic, const test::Payload& p) {
  return dds::safe_deserialize_payload(topic, p.data(), p.size());
}

TEST(SafeDeserializePayload, WellFormedSamplesOfEveryTopicPass) {
  for (Topic topic : kAll) {
    SCOPED_TRACE(std::string(dds::topic_info(topic).short_name));
    EXPECT_TRUE(check(topic, valid_payload(topic)));
  }
  EXPECT_TRUE(check(Topic::kOperatorCommand,
                    test::operator_command_payload(1, "", {0.0, 0.0, 0.0}, false)));
}

TEST(SafeDeserializePayload, MalformedSamplesAreRejected) {
  for (Topic topic : kAll) {
    for (test::Malformation m : test::malformations_of(topic)) {
      SCOPED_TRACE(std::string(dds::topic_info(topic).short_name) + ": " + test::to_string(m));
      EXPECT_FALSE(check(topic, test::malformed_payload(topic, m)));
    }
  }
  // Nothing, or less than an encapsulation header.
  for (Topic topic : kAll) {
    EXPECT_FALSE(dds::safe_deserialize_payload(topic, nullptr, 0));
    const std::uint8_t header[] = {0x00, 0x01};
    EXPECT_FALSE(dds::safe_deserialize_payload(topic, header, sizeof header));
  }
  // A payload of one type is not one of another (operator_command is shorter than a status).
  EXPECT_FALSE(check(Topic::kStatus, valid_payload(Topic::kOperatorCommand)));
}

// Every cut and random byte mutations of each well-formed payload: a result, never an exception
// or a crash (the function is noexcept: an exception would end the test program).
TEST(SafeDeserializePayload, AnyBytesGiveAnAnswer) {
  std::mt19937 rng(20240613);
  int rejected = 0, runs = 0;
  for (Topic topic : kAll) {
    const test::Payload valid = valid_payload(topic);
    for (std::size_t n = 0; n < valid.size(); ++n) {
      const test::Payload cut(valid.begin(), valid.begin() + static_cast<std::ptrdiff_t>(n));
      rejected += check(topic, cut) ? 0 : 1;
      ++runs;
    }
    for (int i = 0; i < 2000; ++i) {
      test::Payload p = valid;
      const int flips = 1 + static_cast<int>(rng() % 4);
      for (int k = 0; k < flips; ++k) p[rng() % p.size()] = static_cast<std::uint8_t>(rng());
      rejected += check(topic, p) ? 0 : 1;
      ++runs;
    }
  }
  EXPECT_GT(rejected, 0);
  EXPECT_LT(rejected, runs);  // most single-byte changes of a double still deserialize
}

}  // namespace
}  // namespace craneassist
