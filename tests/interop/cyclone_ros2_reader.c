/* A ROS 2 subscriber's view of craneassist's ROS 2 topics (docs/ros.md), without ROS 2: an
 * Eclipse Cyclone DDS reader (the default middleware of several ROS 2 releases) whose types
 * Cyclone's idlc generates from ROS 2's own .msg definitions (ros2_msg_to_idl.py), with ROS 2's
 * default subscription QoS (reliable, volatile, keep last 10). It reads
 *   rt<NS>/joint_states                        sensor_msgs/msg/JointState
 *   rt<NS>/craneassist/tip_velocity/command    geometry_msgs/msg/TwistStamped
 *   rt<NS>/craneassist/tip_velocity/reference  geometry_msgs/msg/TwistStamped
 * and craneassist's own craneassist/status and craneassist/joints, until a status says `stopped`
 * or SECONDS pass, and checks:
 *   - JointState: the joint names are JOINTS (the URDF's), one position and velocity per joint,
 *     no effort, finite; the stamp is this host's wall clock a moment ago; the last positions
 *     equal the last q of craneassist/joints (the same cycle, as the run's final sample);
 *   - TwistStamped: frame base_link, no angular part, the stamp as above; the command is
 *     COMMAND (the replay's constant command, in base_link) in at least one sample; every
 *     nonzero reference points along COMMAND (one scale factor on the whole motion).
 *
 * Usage: cyclone_ros2_reader DOMAIN SECONDS NAMESPACE JOINTS COMMAND
 *   NAMESPACE: "" or /name; JOINTS: slew,lift,tilt,extension; COMMAND: vx,vy,vz (m/s, base_link)
 * Exit 0: every check passed; 1: a check failed (each on stderr); 2: usage; 3: DDS failed.
 * "cyclone ros2 reader: ready" on stdout once the readers exist. */
#define _POSIX_C_SOURCE 200809L /* clock_gettime */
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "craneassist_msgs.h"
#include "cyclone_common.h"
#include "dds/dds.h"
#include "ros2_msgs_from_msg.h"

enum { kJointStates, kCommand, kReference, kStatus, kJoints, kTopics };
static const char* const kNames[kTopics] = {"joint_states", "tip_velocity/command",
                                            "tip_velocity/reference", "craneassist/status",
                                            "craneassist/joints"};

#define CHECK(cond, topic, ...) CHECK_AS("cyclone ros2 reader", kNames[topic], cond, __VA_ARGS__)

static long g_count[kTopics];
static char* g_joint_names[8];
static int g_dof = 0;
static double g_command[3];
static long g_command_matches = 0, g_command_nan = 0, g_reference_moving = 0;
static double g_last_position[8], g_last_q[8];
static int g_last_position_n = -1, g_last_q_n = -1;
static double g_stamp_age_max_s = 0.0;

/* ROS 2's graph (docs/ros.md): the endpoints' USER_DATA type hashes, the participant's enclave,
   and the node ros_discovery_info names, with the GUIDs of its writers. */
enum { kMaxEndpoints = 8 };
static const char* g_node_name = NULL;
static const char* g_expected_hash[3] = {NULL, NULL, NULL}; /* JointState, TwistStamped, PEI */
static char g_ros_topics[3][256];
static dds_guid_t g_writer_guid[3];
static int g_writer_seen[3] = {0, 0, 0};
static dds_guid_t g_participant;
static int g_participant_known = 0, g_enclave_ok = 0, g_discovery_ok = 0, g_discovery_samples = 0;
static char g_discovery_node[600] = "";
static char g_discovery_user_data[128] = ""; /* craneassist's ros_discovery_info writer's */
/* The range each JointState position took over the run (the hanger joints must swing). */
static double g_position_min[8], g_position_max[8];
static const double kPi = 3.14159265358979323846;
static char g_last_status[32] = "";

static int64_t wall_ns(void) {
  struct timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);
  return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

/* A ROS 2 header: stamped with this host's wall clock within the last 2 s. */
static void check_header(int topic, const std_msgs_msg_dds__Header_* h, const char* frame_id) {
  const int64_t stamp = (int64_t)h->stamp.sec * 1000000000 + h->stamp.nanosec;
  const double age_s = (double)(wall_ns() - stamp) * 1e-9;
  CHECK(h->stamp.nanosec < 1000000000u, topic, "nanosec %u", h->stamp.nanosec);
  CHECK(age_s > -0.01 && age_s < 2.0, topic, "stamp %d.%09u is %.3f s old", h->stamp.sec,
        h->stamp.nanosec, age_s);
  if (age_s > g_stamp_age_max_s) g_stamp_age_max_s = age_s;
  CHECK(h->frame_id != NULL && strcmp(h->frame_id, frame_id) == 0, topic,
        "frame_id '%s', expected '%s'", h->frame_id ? h->frame_id : "(null)", frame_id);
}

static void check_joint_state(const sensor_msgs_msg_dds__JointState_* m) {
  check_header(kJointStates, &m->header, "");
  CHECK((int)m->name._length == g_dof, kJointStates, "%u names", m->name._length);
  for (uint32_t i = 0; i < m->name._length && (int)i < g_dof; ++i) {
    CHECK(strcmp(m->name._buffer[i], g_joint_names[i]) == 0, kJointStates, "name %u '%s'", i,
          m->name._buffer[i]);
  }
  CHECK((int)m->position._length == g_dof, kJointStates, "%u positions", m->position._length);
  CHECK((int)m->velocity._length == g_dof, kJointStates, "%u velocities", m->velocity._length);
  CHECK(m->effort._length == 0, kJointStates, "%u efforts", m->effort._length);
  for (uint32_t i = 0; i < m->position._length && i < 8; ++i) {
    const double p = m->position._buffer[i];
    CHECK(isfinite(p), kJointStates, "position %u", i);
    if (g_count[kJointStates] == 1 || p < g_position_min[i]) g_position_min[i] = p;
    if (g_count[kJointStates] == 1 || p > g_position_max[i]) g_position_max[i] = p;
    g_last_position[i] = p;
  }
  for (uint32_t i = 0; i < m->velocity._length; ++i) {
    CHECK(isfinite(m->velocity._buffer[i]), kJointStates, "velocity %u", i);
  }
  g_last_position_n = (int)m->position._length;
}

static void check_twist(int topic, const geometry_msgs_msg_dds__TwistStamped_* m) {
  check_header(topic, &m->header, "base_link");
  const geometry_msgs_msg_dds__Vector3_* a = &m->twist.angular;
  CHECK(a->x == 0.0 && a->y == 0.0 && a->z == 0.0, topic, "angular %g %g %g", a->x, a->y, a->z);
  const double v[3] = {m->twist.linear.x, m->twist.linear.y, m->twist.linear.z};
  if (topic == kCommand) {
    /* NaN: no valid operator command (the replay's start and end); else the replay's. */
    if (isnan(v[0]) && isnan(v[1]) && isnan(v[2])) {
      ++g_command_nan;
      return;
    }
    CHECK(isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]), topic, "linear %g %g %g", v[0], v[1],
          v[2]);
    if (fabs(v[0] - g_command[0]) < 1e-12 && fabs(v[1] - g_command[1]) < 1e-12 &&
        fabs(v[2] - g_command[2]) < 1e-12) {
      ++g_command_matches;
    }
    return;
  }
  CHECK(isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]), topic, "linear %g %g %g", v[0], v[1],
        v[2]);
  const double speed = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (speed < 1e-6) return;
  ++g_reference_moving;
  const double c =
      sqrt(g_command[0] * g_command[0] + g_command[1] * g_command[1] + g_command[2] * g_command[2]);
  const double cosine =
      (v[0] * g_command[0] + v[1] * g_command[1] + v[2] * g_command[2]) / (speed * c);
  CHECK(cosine > 1.0 - 1e-9, topic, "linear %g %g %g is not along the command (cos %.12f)", v[0],
        v[1], v[2], cosine);
}

static void take_all(dds_entity_t reader, int topic) {
  enum { kMax = 64 };
  void* samples[kMax] = {NULL};
  dds_sample_info_t infos[kMax];
  const dds_return_t n = dds_or_exit(dds_take(reader, samples, infos, kMax, kMax),
                                     "cyclone ros2 reader", "dds_take", kNames[topic]);
  for (dds_return_t i = 0; i < n; ++i) {
    if (!infos[i].valid_data) continue;
    ++g_count[topic];
    if (topic == kJointStates) {
      check_joint_state(samples[i]);
    } else if (topic == kCommand || topic == kReference) {
      check_twist(topic, samples[i]);
    } else if (topic == kStatus) {
      const craneassist_msg_Status* s = samples[i];
      snprintf(g_last_status, sizeof g_last_status, "%s", s->state ? s->state : "");
    } else {
      const craneassist_msg_JointState* j = samples[i];
      for (uint32_t k = 0; k < j->q._length && k < 8; ++k) g_last_q[k] = j->q._buffer[k];
      g_last_q_n = (int)j->q._length;
    }
  }
  if (n > 0) dds_return_loan(reader, samples, n);
}

/* A writer of one of the ROS 2 topics: its type hash, its participant (craneassist's). */
static void check_publications(dds_entity_t reader) {
  enum { kMax = 32 };
  void* samples[kMax] = {NULL};
  dds_sample_info_t infos[kMax];
  const dds_return_t n = dds_take(reader, samples, infos, kMax, kMax);
  for (dds_return_t i = 0; i < n; ++i) {
    if (!infos[i].valid_data) continue;
    const dds_builtintopic_endpoint_t* e = samples[i];
    if (strcmp(e->topic_name, "ros_discovery_info") == 0 && g_participant_known &&
        memcmp(&e->participant_key, &g_participant, sizeof g_participant) == 0) {
      void* value = NULL;
      size_t size = 0;
      if (dds_qget_userdata(e->qos, &value, &size) && value != NULL) {
        snprintf(g_discovery_user_data, sizeof g_discovery_user_data, "%.*s", (int)size,
                 (const char*)value);
      }
      dds_free(value);
    }
    for (int t = 0; t < 3; ++t) {
      if (strcmp(e->topic_name, g_ros_topics[t]) != 0) continue;
      void* value = NULL;
      size_t size = 0;
      char text[128] = "";
      if (dds_qget_userdata(e->qos, &value, &size) && value != NULL) {
        snprintf(text, sizeof text, "%.*s", (int)size, (const char*)value);
      }
      dds_free(value);
      char expected[128];
      snprintf(expected, sizeof expected, "typehash=%s;", g_expected_hash[t == 0 ? 0 : 1]);
      CHECK(strcmp(text, expected) == 0, t, "USER_DATA '%s', expected '%s'", text, expected);
      g_writer_guid[t] = e->key;
      g_writer_seen[t] = 1;
      if (!g_participant_known) g_participant = e->participant_key;
      CHECK(memcmp(&g_participant, &e->participant_key, sizeof g_participant) == 0, t,
            "a writer of another participant");
      g_participant_known = 1;
    }
  }
  if (n > 0) dds_return_loan(reader, samples, n);
}

/* craneassist's participant: ROS 2's `enclave=/;` in its USER_DATA (rmw writes its NUL too). */
static void check_participants(dds_entity_t reader) {
  enum { kMax = 32 };
  void* samples[kMax] = {NULL};
  dds_sample_info_t infos[kMax];
  const dds_return_t n = dds_read(reader, samples, infos, kMax, kMax);
  for (dds_return_t i = 0; g_participant_known && i < n; ++i) {
    if (!infos[i].valid_data) continue;
    const dds_builtintopic_participant_t* p = samples[i];
    if (memcmp(&p->key, &g_participant, sizeof g_participant) != 0) continue;
    void* value = NULL;
    size_t size = 0;
    if (dds_qget_userdata(p->qos, &value, &size) && value != NULL) {
      g_enclave_ok = (size == 11 && memcmp(value, "enclave=/;", 11) == 0) ||
                     (size == 10 && memcmp(value, "enclave=/;", 10) == 0);
    }
    dds_free(value);
  }
  if (n > 0) dds_return_loan(reader, samples, n);
}

/* ros_discovery_info: craneassist's participant names one node, whose writers are the three. */
static void check_discovery(dds_entity_t reader) {
  enum { kMax = 16 };
  void* samples[kMax] = {NULL};
  dds_sample_info_t infos[kMax];
  const dds_return_t n = dds_take(reader, samples, infos, kMax, kMax);
  for (dds_return_t i = 0; i < n; ++i) {
    if (!infos[i].valid_data || !g_participant_known) continue;
    const rmw_dds_common_msg_dds__ParticipantEntitiesInfo_* m = samples[i];
    if (memcmp(m->gid.data, g_participant.v, 16) != 0) continue;
    ++g_discovery_samples;
    CHECK(m->node_entities_info_seq._length == 1, kJointStates, "%u nodes",
          m->node_entities_info_seq._length);
    if (m->node_entities_info_seq._length < 1) continue;
    const rmw_dds_common_msg_dds__NodeEntitiesInfo_* node = &m->node_entities_info_seq._buffer[0];
    snprintf(g_discovery_node, sizeof g_discovery_node, "%s%s%s", node->node_namespace,
             strcmp(node->node_namespace, "/") == 0 ? "" : "/", node->node_name);
    int found = 0;
    for (int t = 0; t < 3; ++t) {
      for (uint32_t k = 0; g_writer_seen[t] && k < node->writer_gid_seq._length; ++k) {
        found += memcmp(node->writer_gid_seq._buffer[k].data, g_writer_guid[t].v, 16) == 0;
      }
    }
    CHECK(strcmp(node->node_name, g_node_name) == 0, kJointStates, "node '%s', expected '%s'",
          node->node_name, g_node_name);
    CHECK(node->reader_gid_seq._length == 0, kJointStates, "%u readers",
          node->reader_gid_seq._length);
    CHECK(node->writer_gid_seq._length == 3 && found == 3, kJointStates,
          "%u writers, %d of them the three ROS 2 topics'", node->writer_gid_seq._length, found);
    g_discovery_ok = strcmp(node->node_name, g_node_name) == 0 &&
                     node->writer_gid_seq._length == 3 && found == 3;
  }
  if (n > 0) dds_return_loan(reader, samples, n);
}

static dds_entity_t make_reader(dds_entity_t pp, const dds_topic_descriptor_t* desc,
                                const char* name, dds_qos_t* qos) {
  return create_endpoint_or_exit(dds_create_reader, "dds_create_reader", pp, desc, name, qos,
                                 "cyclone ros2 reader");
}

/* ROS 2's default subscription QoS (rmw_qos_profile_default). */
static dds_qos_t* ros2_default_qos(void) {
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 10);
  return qos;
}

int main(int argc, char** argv) {
  if (argc != 10 ||
      sscanf(argv[5], "%lf,%lf,%lf", &g_command[0], &g_command[1], &g_command[2]) != 3) {
    fprintf(stderr,
            "usage: cyclone_ros2_reader DOMAIN SECONDS NAMESPACE JOINTS VX,VY,VZ NODE "
            "JOINTSTATE_HASH TWISTSTAMPED_HASH PARTICIPANTENTITIESINFO_HASH\n");
    return 2;
  }
  g_node_name = argv[6];
  g_expected_hash[0] = argv[7];
  g_expected_hash[1] = argv[8];
  g_expected_hash[2] = argv[9];
  const dds_domainid_t domain = (dds_domainid_t)atoi(argv[1]);
  const double seconds = atof(argv[2]);
  const char* ns = argv[3];
  for (char* name = strtok(argv[4], ","); name != NULL && g_dof < 8; name = strtok(NULL, ",")) {
    g_joint_names[g_dof++] = name;
  }
  char names[3][256];
  snprintf(names[0], sizeof names[0], "rt%s/joint_states", ns);
  snprintf(names[1], sizeof names[1], "rt%s/craneassist/tip_velocity/command", ns);
  snprintf(names[2], sizeof names[2], "rt%s/craneassist/tip_velocity/reference", ns);
  for (int t = 0; t < 3; ++t) snprintf(g_ros_topics[t], sizeof g_ros_topics[t], "%s", names[t]);

  const dds_entity_t pp = create_participant_or_exit(domain, "cyclone ros2 reader");
  const dds_entity_t readers[kTopics] = {
      make_reader(pp, &sensor_msgs_msg_dds__JointState__desc, names[0], ros2_default_qos()),
      make_reader(pp, &geometry_msgs_msg_dds__TwistStamped__desc, names[1], ros2_default_qos()),
      make_reader(pp, &geometry_msgs_msg_dds__TwistStamped__desc, names[2], ros2_default_qos()),
      make_reader(pp, &craneassist_msg_Status_desc, "craneassist/status",
                  craneassist_qos(true, DDS_SECS(1), 16)),
      make_reader(pp, &craneassist_msg_JointState_desc, "craneassist/joints",
                  craneassist_qos(false, 0, 16))};
  const dds_entity_t publications =
      dds_or_exit(dds_create_reader(pp, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, NULL, NULL),
                  "cyclone ros2 reader", "dds_create_reader", "DCPSPublication");
  const dds_entity_t participants =
      dds_or_exit(dds_create_reader(pp, DDS_BUILTIN_TOPIC_DCPSPARTICIPANT, NULL, NULL),
                  "cyclone ros2 reader", "dds_create_reader", "DCPSParticipant");
  /* ros_discovery_info as a ROS 2 node reads it: reliable, transient local, keep all. */
  dds_qos_t* discovery_qos = dds_create_qos();
  dds_qset_reliability(discovery_qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(discovery_qos, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_history(discovery_qos, DDS_HISTORY_KEEP_ALL, 0);
  const dds_entity_t discovery =
      make_reader(pp, &rmw_dds_common_msg_dds__ParticipantEntitiesInfo__desc, "ros_discovery_info",
                  discovery_qos);
  printf("cyclone ros2 reader: ready on domain %d\n", (int)domain);
  fflush(stdout);

  const int64_t start = monotonic_ns();
  int64_t stopped_at = 0;
  while ((double)(monotonic_ns() - start) * 1e-9 < seconds) {
    if (stopped_at != 0 && monotonic_ns() - stopped_at > 500000000) break;
    for (int t = 0; t < kTopics; ++t) take_all(readers[t], t);
    check_publications(publications);
    check_participants(participants);
    check_discovery(discovery);
    if (stopped_at == 0 && strcmp(g_last_status, "stopped") == 0) stopped_at = monotonic_ns();
    dds_sleepfor(DDS_MSECS(5));
  }
  dds_delete(pp);

  /* The crane's joints first, as craneassist/joints has them; after them the URDF's hanger
     joints of a hanging grapple, which the grapple's swing turns (the replay starts moving). */
  double last_diff = 0.0;
  bool same_joints = g_last_position_n == g_dof && g_last_q_n > 0 && g_last_q_n <= g_dof;
  for (int i = 0; same_joints && i < g_last_q_n; ++i) {
    last_diff = fmax(last_diff, fabs(g_last_position[i] - g_last_q[i]));
  }
  CHECK(same_joints && last_diff == 0.0, kJointStates,
        "last positions differ from the last craneassist/joints q by %g", last_diff);
  double hanger_range = 0.0;
  for (int i = g_last_q_n; same_joints && i < g_dof; ++i) {
    const double range = g_position_max[i] - g_position_min[i];
    CHECK(g_position_min[i] >= -kPi && g_position_max[i] <= kPi, kJointStates,
          "%s from %g to %g rad", g_joint_names[i], g_position_min[i], g_position_max[i]);
    if (range > hanger_range) hanger_range = range;
  }
  CHECK(!same_joints || g_dof == g_last_q_n || hanger_range > 1e-3, kJointStates,
        "the hanger joints never moved (range %g rad)", hanger_range);
  CHECK(g_command_matches > 0, kCommand, "never (%g, %g, %g)", g_command[0], g_command[1],
        g_command[2]);
  CHECK(g_writer_seen[0] && g_writer_seen[1] && g_writer_seen[2], kJointStates,
        "the ROS 2 writers' discovery data not seen");
  CHECK(g_enclave_ok, kJointStates, "craneassist's participant has no enclave=/; USER_DATA");
  CHECK(g_discovery_ok, kJointStates, "no ros_discovery_info of craneassist's participant");
  char discovery_hash[128];
  snprintf(discovery_hash, sizeof discovery_hash, "typehash=%s;", g_expected_hash[2]);
  CHECK(strcmp(g_discovery_user_data, discovery_hash) == 0, kJointStates,
        "ros_discovery_info writer's USER_DATA '%s', expected '%s'", g_discovery_user_data,
        discovery_hash);
  CHECK(g_reference_moving > 0, kReference, "never moving");
  printf(
      "cyclone ros2 reader: received joint_states %ld, tip_velocity/command %ld, "
      "tip_velocity/reference %ld; status %ld, joints %ld; last status '%s'; command "
      "(%g, %g, %g) in %ld samples, NaN in %ld; %ld moving references along it; last positions "
      "= last craneassist q: %s; %d hanger joints, swinging over %.4f rad; stamp age max %.1f ms; "
      "%ld failed checks\n"
      "cyclone ros2 reader: graph: the writers' USER_DATA type hashes as expected: %s; "
      "participant enclave=/;: %s; ros_discovery_info samples %d, node %s with the three "
      "writers: %s\n",
      g_count[kJointStates], g_count[kCommand], g_count[kReference], g_count[kStatus],
      g_count[kJoints], g_last_status, g_command[0], g_command[1], g_command[2], g_command_matches,
      g_command_nan, g_reference_moving, same_joints && last_diff == 0.0 ? "yes" : "no",
      g_dof - g_last_q_n, hanger_range, 1e3 * g_stamp_age_max_s, *check_errors(),
      g_writer_seen[0] && g_writer_seen[1] && g_writer_seen[2] ? "yes" : "no",
      g_enclave_ok ? "yes" : "no", g_discovery_samples, g_discovery_node,
      g_discovery_ok ? "yes" : "no");
  bool ok = *check_errors() == 0;
  for (int t = 0; t < kTopics; ++t) {
    if (g_count[t] == 0) {
      fprintf(stderr, "cyclone ros2 reader: no sample on %s\n", kNames[t]);
      ok = false;
    }
  }
  return ok ? 0 : 1;
}
