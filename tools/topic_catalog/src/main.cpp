// rigger-topic-catalog: prints docs/topics.md, generated from the topic descriptors of common/protocol
// (tools/update-topic-reference writes it).
#include <iostream>

#include "rigger/protocol/catalog.hpp"

int main() {
  std::cout << rigger::protocol::catalog_markdown();
  return 0;
}
