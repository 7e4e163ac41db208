#pragma once
/// @file
/// Typed writers and readers over idlc-generated structs. Samples are taken on loan and the loan is
/// returned by a guard; writes never throw in steady state (they return the DDS return code).

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>

#include <rigger/idl/types.hpp>

#include "rigger/dds/entity.hpp"
#include "rigger/dds/participant.hpp"
#include "rigger/dds/qos.hpp"

namespace rigger::dds {

/// Returns a loan of samples to the reader when it goes out of scope.
class LoanGuard {
 public:
  LoanGuard(dds_entity_t reader, void** buffer, int32_t count) : reader_(reader), buffer_(buffer), count_(count) {}
  LoanGuard(const LoanGuard&) = delete;
  LoanGuard& operator=(const LoanGuard&) = delete;
  ~LoanGuard() {
    if (count_ > 0) dds_return_loan(reader_, buffer_, count_);
  }

 private:
  dds_entity_t reader_;
  void** buffer_;
  int32_t count_;
};

/// Creates the topic `name` of type T in `participant`. @throws DdsError.
template <typename T>
Entity make_topic(const Participant& participant, const std::string& name) {
  return Entity(dds_create_topic(participant.handle(), idl::TypeSupport<T>::descriptor(), name.c_str(), nullptr, nullptr),
                ("create topic " + name).c_str());
}

/// A typed DataWriter for topic `name`. Thread-safe (Cyclone writers are).
template <typename T>
class Writer {
 public:
  Writer() = default;
  Writer(const Participant& participant, const std::string& name, const Qos& qos)
      : topic_name_(name),
        topic_(make_topic<T>(participant, name)),
        writer_(dds_create_writer(participant.handle(), topic_.handle(), qos.get(), nullptr),
                ("create writer " + name).c_str()) {}
  /// A writer of the descriptor's topic with its QoS profile (rigger/protocol/<area>.hpp).
  Writer(const Participant& participant, const protocol::Topic<T>& topic)
      : Writer(participant, topic.name, qos::of(topic.qos)) {}
  /// A writer of the descriptor's topic with another QoS (e.g. a longer liveliness lease).
  Writer(const Participant& participant, const protocol::Topic<T>& topic, const Qos& qos)
      : Writer(participant, topic.name, qos) {}

  /// Publishes `sample`; returns DDS_RETCODE_OK or the error. Never throws.
  dds_return_t write(const T& sample) const noexcept { return dds_write(writer_.handle(), &sample); }
  /// Disposes the instance whose key fields `sample` carries.
  dds_return_t dispose(const T& sample) const noexcept { return dds_dispose(writer_.handle(), &sample); }
  /// Unregisters the instance whose key fields `sample` carries.
  dds_return_t unregister(const T& sample) const noexcept { return dds_unregister_instance(writer_.handle(), &sample); }

  /// Number of readers currently matched.
  uint32_t matched_readers() const {
    dds_publication_matched_status_t st{};
    dds_get_publication_matched_status(writer_.handle(), &st);
    return st.current_count;
  }
  /// Blocks until at least `count` readers match or `timeout` passes (a waitset on the writer's
  /// status, no polling). Returns whether they matched. For tools and setup, not for loops.
  bool wait_for_readers(uint32_t count, std::chrono::nanoseconds timeout) const;

  dds_entity_t handle() const { return writer_.handle(); }
  const std::string& topic_name() const { return topic_name_; }

 private:
  std::string topic_name_;
  Entity topic_;
  Entity writer_;  // declared after topic_: destroyed first
};

/// A typed DataReader for topic `name`. Use from one thread (the service's event loop).
template <typename T>
class Reader {
 public:
  Reader() = default;
  Reader(const Participant& participant, const std::string& name, const Qos& qos)
      : topic_name_(name),
        topic_(make_topic<T>(participant, name)),
        reader_(dds_create_reader(participant.handle(), topic_.handle(), qos.get(), nullptr),
                ("create reader " + name).c_str()) {}
  /// A reader of the descriptor's topic with its QoS profile (rigger/protocol/<area>.hpp).
  Reader(const Participant& participant, const protocol::Topic<T>& topic)
      : Reader(participant, topic.name, qos::of(topic.qos)) {}
  /// A reader of the descriptor's topic with another QoS, e.g. qos::state_changes() on a state() topic.
  Reader(const Participant& participant, const protocol::Topic<T>& topic, const Qos& qos)
      : Reader(participant, topic.name, qos) {}

  /// Takes every available sample: `on_sample(const T&, const dds_sample_info_t&)` for each valid one.
  /// Instance-state notifications (disposed, no writers) are skipped. Returns the number taken or a
  /// negative DDS return code.
  template <typename OnSample>
  int32_t take(OnSample&& on_sample) {
    return take(std::forward<OnSample>(on_sample), [](const T&, const dds_sample_info_t&) {});
  }
  /// As take(on_sample), and `on_instance(const T& key_only, const dds_sample_info_t&)` for instance-state
  /// notifications (only the key fields of the sample are valid then).
  template <typename OnSample, typename OnInstance>
  int32_t take(OnSample&& on_sample, OnInstance&& on_instance) {
    constexpr int32_t kBatch = 32;
    int32_t total = 0;
    for (;;) {
      void* buffer[kBatch] = {};
      dds_sample_info_t info[kBatch];
      const int32_t n = dds_take(reader_.handle(), buffer, info, kBatch, kBatch);
      if (n < 0) return n;
      LoanGuard guard(reader_.handle(), buffer, n);
      for (int32_t i = 0; i < n; ++i) {
        const T& sample = *static_cast<const T*>(buffer[i]);
        if (info[i].valid_data) on_sample(sample, info[i]);
        else on_instance(sample, info[i]);
      }
      total += n;
      if (n < kBatch) return total;
    }
  }

  /// Number of writers currently matched.
  uint32_t matched_writers() const {
    dds_subscription_matched_status_t st{};
    dds_get_subscription_matched_status(reader_.handle(), &st);
    return st.current_count;
  }
  /// Blocks until at least `count` writers match or `timeout` passes (a waitset on the reader's
  /// status, no polling). Returns whether they matched. Matching is not symmetric in time: a writer
  /// of ours may see a service's reader before that service's writers see our reader, so a test that
  /// sends a command and expects every reply waits for both. For tools and setup, not for loops.
  bool wait_for_writers(uint32_t count, std::chrono::nanoseconds timeout) const;

  dds_entity_t handle() const { return reader_.handle(); }
  const std::string& topic_name() const { return topic_name_; }

 private:
  std::string topic_name_;
  Entity topic_;
  Entity reader_;
};

/// Blocks on a waitset until `entity`'s `status` has been raised and `done()` holds, or `timeout`.
bool wait_for_status(dds_entity_t entity, uint32_t status, const std::function<bool()>& done,
                     std::chrono::nanoseconds timeout);

template <typename T>
bool Writer<T>::wait_for_readers(uint32_t count, std::chrono::nanoseconds timeout) const {
  return wait_for_status(writer_.handle(), DDS_PUBLICATION_MATCHED_STATUS,
                         [&] { return matched_readers() >= count; }, timeout);
}

template <typename T>
bool Reader<T>::wait_for_writers(uint32_t count, std::chrono::nanoseconds timeout) const {
  return wait_for_status(reader_.handle(), DDS_SUBSCRIPTION_MATCHED_STATUS,
                         [&] { return matched_writers() >= count; }, timeout);
}

}  // namespace rigger::dds
