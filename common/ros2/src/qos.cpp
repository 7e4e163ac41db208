#include "rigger/ros2/qos.hpp"

namespace rigger::ros2::qos {

dds::Qos sensor_data() {
  dds::Qos q;
  q.best_effort().keep_last(5).volatile_durability();
  return q;
}

dds::Qos reliable_default() {
  dds::Qos q;
  q.reliable().keep_last(10).volatile_durability();
  return q;
}

dds::Qos system_default() {
  dds::Qos q;
  q.reliable().keep_last(1).volatile_durability();
  return q;
}

}  // namespace rigger::ros2::qos
