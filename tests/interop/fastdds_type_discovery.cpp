// A Fast DDS 2.9 dynamic-type reader's view of craneassist's types (docs/telemetry.md,
// "Nested types and dynamic-type tools"): a participant that knows none of craneassist's types
// and builds them from what discovery announces, from the type object in the endpoints'
// discovery data (on_type_discovery) or through the TypeLookup service from TYPE_INFORMATION
// (on_type_information_received, register_remote_type). Prints each telemetry topic's type once:
//
//   type_object craneassist/status: craneassist::msg::Status, 19 members: active_limit ...
//
// Usage: fastdds_type_discovery DOMAIN SECONDS. Ends when the four telemetry topics have a type,
// or after SECONDS. Must run in another process than craneassist: a process that registered the
// generated types resolves nested types from its own registry.
#include <fastrtps/types/DynamicType.h>
#include <fastrtps/types/DynamicTypeMember.h>
#include <fastrtps/types/DynamicTypePtr.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <functional>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <thread>

namespace {

namespace fdds = eprosima::fastdds::dds;
namespace types = eprosima::fastrtps::types;

std::mutex g_mutex;
std::set<std::string> g_topics;  // telemetry topics with a type printed

void print(const char* how, const std::string& topic, const types::DynamicType_ptr& type) {
  if (topic.rfind("craneassist/", 0) != 0) return;
  std::lock_guard<std::mutex> lock(g_mutex);
  if (!g_topics.insert(topic).second) return;
  std::map<std::string, types::DynamicTypeMember*> members;
  if (type) type->get_all_members_by_name(members);
  std::printf("%s %s: %s, %zu members:", how, topic.c_str(),
              type ? type->get_name().c_str() : "(no type)", members.size());
  for (const auto& m : members) std::printf(" %s", m.first.c_str());
  std::printf("\n");
  std::fflush(stdout);
}

class Listener : public fdds::DomainParticipantListener {
 public:
  void on_type_discovery(fdds::DomainParticipant* /*participant*/,
                         const eprosima::fastrtps::rtps::SampleIdentity& /*request*/,
                         const eprosima::fastrtps::string_255& topic,
                         const types::TypeIdentifier* /*identifier*/,
                         const types::TypeObject* /*object*/,
                         types::DynamicType_ptr type) override {
    print("type_object", topic.to_string(), type);
  }
  void on_type_information_received(fdds::DomainParticipant* participant,
                                    const eprosima::fastrtps::string_255 topic_name,
                                    const eprosima::fastrtps::string_255 type_name,
                                    const types::TypeInformation& information) override {
    const std::string topic = topic_name.to_string();
    std::function<void(const std::string&, const types::DynamicType_ptr)> done =
        [topic](const std::string&, const types::DynamicType_ptr type) {
          print("type_lookup", topic, type);
        };
    participant->register_remote_type(information, type_name.to_string(), done);
  }
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: fastdds_type_discovery DOMAIN SECONDS\n");
    return 2;
  }
  fdds::DomainParticipantQos qos = fdds::PARTICIPANT_QOS_DEFAULT;
  qos.name("fastdds_type_discovery");
  qos.wire_protocol().builtin.typelookup_config.use_client = true;
  Listener listener;
  fdds::DomainParticipant* participant =
      fdds::DomainParticipantFactory::get_instance()->create_participant(std::atoi(argv[1]), qos,
                                                                         &listener);
  if (participant == nullptr) {
    std::fprintf(stderr, "fastdds_type_discovery: cannot create the participant\n");
    return 3;
  }
  std::printf("fastdds_type_discovery: ready\n");
  std::fflush(stdout);
  const auto end =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(std::atof(argv[2]));
  while (std::chrono::steady_clock::now() < end) {
    {
      std::lock_guard<std::mutex> lock(g_mutex);
      if (g_topics.size() >= 4) break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  participant->set_listener(nullptr);
  fdds::DomainParticipantFactory::get_instance()->delete_participant(participant);
  return 0;
}
