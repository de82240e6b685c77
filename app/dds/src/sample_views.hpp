// What `craneassist echo` and `craneassist dashboard` make of received samples, without a DDS
// reader around them (internal to the dds module: Fast DDS types, C++17). For the fuzz harness
// of the DDS samples (tests/fuzz/fuzz_dds_samples.cpp), which hands them deserialized bytes.
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include "craneassist/dds/tools.hpp"
#include "craneassist_msgs.h"

namespace craneassist::dds {

// One sample as echo prints it to `out`: a text block, or for kCsv the header line and the
// sample's row.
void echo_sample(const msg::Status& sample, EchoFormat format, std::FILE* out);
void echo_sample(const msg::JointState& sample, EchoFormat format, std::FILE* out);
void echo_sample(const msg::Hydraulics& sample, EchoFormat format, std::FILE* out);
void echo_sample(const msg::CommandPath& sample, EchoFormat format, std::FILE* out);
void echo_sample(const msg::OperatorCommand& sample, EchoFormat format, std::FILE* out);
void echo_sample(const msg::BaseState& sample, EchoFormat format, std::FILE* out);
void echo_sample(const msg::FieldValues& sample, EchoFormat format, std::FILE* out);

// The dashboard's plain view (as --once prints it) of the latest sample of each telemetry topic;
// nullptr: none received yet (base: a crane without a wheeled base).
std::vector<std::string> dashboard_view(const msg::Status* status, const msg::JointState* joints,
                                        const msg::Hydraulics* hydraulics,
                                        const msg::CommandPath* command_path,
                                        const msg::BaseState* base = nullptr);

}  // namespace craneassist::dds
