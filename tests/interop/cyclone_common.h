/* What the Cyclone DDS programs of the interop tests share (cyclone_reader.c, cyclone_writer.c,
 * cyclone_ros2_reader.c): the clock of the telemetry headers' stamp_ns, a topic with
 * craneassist's QoS, and the readers' checks. */
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

/* The topic `name` on pp; exits 3 (naming `who`) when Cyclone refuses it. */
static inline dds_entity_t create_topic_or_exit(dds_entity_t pp, const dds_topic_descriptor_t* desc,
                                                const char* name, const char* who) {
  const dds_entity_t topic = dds_create_topic(pp, desc, name, NULL, NULL);
  if (topic < 0) {
    fprintf(stderr, "%s: dds_create_topic %s: %s\n", who, name, dds_strretcode(-topic));
    exit(3);
  }
  return topic;
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
