/* What the Cyclone DDS programs of the interop tests share (cyclone_reader.c, cyclone_writer.c,
 * cyclone_ros2_reader.c): the clock of the telemetry headers' stamp_ns, exit 3 when Cyclone
 * fails, the participant, topics with their readers or writers, craneassist's QoS, and the
 * readers' checks. */
#ifndef CRANEASSIST_CYCLONE_COMMON_H
#define CRANEASSIST_CYCLONE_COMMON_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "dds/dds.h"

/* CLOCK_MONOTONIC in ns, the clock of Header.stamp_ns. */
static inline int64_t monotonic_ns(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

/* rc, what the Cyclone call `call` returned for the topic `name` (an entity or a count); exits 3
 * with "WHO: CALL NAME: reason" when it is an error. */
static inline dds_return_t dds_or_exit(dds_return_t rc, const char* who, const char* call,
                                       const char* name) {
  if (rc < 0) {
    fprintf(stderr, "%s: %s %s: %s\n", who, call, name, dds_strretcode(-rc));
    exit(3);
  }
  return rc;
}

/* The participant on `domain`; exits 3 (naming `who`) when Cyclone refuses it. */
static inline dds_entity_t create_participant_or_exit(dds_domainid_t domain, const char* who) {
  const dds_entity_t pp = dds_create_participant(domain, NULL, NULL);
  if (pp < 0) {
    fprintf(stderr, "%s: dds_create_participant: %s\n", who, dds_strretcode(-pp));
    exit(3);
  }
  return pp;
}

/* The topic `name` on pp; exits 3 (naming `who`) when Cyclone refuses it. */
static inline dds_entity_t create_topic_or_exit(dds_entity_t pp, const dds_topic_descriptor_t* desc,
                                                const char* name, const char* who) {
  return dds_or_exit(dds_create_topic(pp, desc, name, NULL, NULL), who, "dds_create_topic", name);
}

/* dds_create_reader or dds_create_writer. */
typedef dds_entity_t (*create_endpoint_fn)(dds_entity_t, dds_entity_t, const dds_qos_t*,
                                           const dds_listener_t*);

/* A reader or a writer (`create`, named `call`) of a new topic `name` on pp with qos, which it
 * frees; exits 3 (naming `who`) when Cyclone refuses the topic or the endpoint. */
static inline dds_entity_t create_endpoint_or_exit(create_endpoint_fn create, const char* call,
                                                   dds_entity_t pp,
                                                   const dds_topic_descriptor_t* desc,
                                                   const char* name, dds_qos_t* qos,
                                                   const char* who) {
  const dds_entity_t topic = create_topic_or_exit(pp, desc, name, who);
  const dds_entity_t endpoint = create(pp, topic, qos, NULL);
  dds_delete_qos(qos);
  return dds_or_exit(endpoint, who, call, name);
}

/* craneassist's default QoS: status reliable (blocking at most max_blocking) and transient
 * local, the other topics best effort and volatile; keep-last `depth`. Free with
 * dds_delete_qos. */
static inline dds_qos_t* craneassist_qos(bool reliable, dds_duration_t max_blocking,
                                         int32_t depth) {
  dds_qos_t* qos = dds_create_qos();
  if (reliable) {
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, max_blocking);
    dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
  } else {
    dds_qset_reliability(qos, DDS_RELIABILITY_BEST_EFFORT, 0);
  }
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, depth);
  return qos;
}

/* The failed checks so far. */
static inline long* check_errors(void) {
  static long errors = 0;
  return &errors;
}

/* A check of a reader: when cond is false, counted, and the first 20 printed as
 * "WHO: WHAT: message (check: cond)". */
#define CHECK_AS(who, what, cond, ...)            \
  do {                                            \
    if (!(cond)) {                                \
      if (++*check_errors() <= 20) {              \
        fprintf(stderr, "%s: %s: ", who, what);   \
        fprintf(stderr, __VA_ARGS__);             \
        fprintf(stderr, " (check: %s)\n", #cond); \
      }                                           \
    }                                             \
  } while (0)

#endif
