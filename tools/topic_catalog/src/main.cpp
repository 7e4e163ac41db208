// rigger-topic-catalog: prints docs/topics.md, generated from the topic descriptors of common/protocol
// (tools/update-topic-reference writes it); with --permissions, the DDS Security access table
// (rigger/protocol/access.hpp) as lines `<identity> publish|subscribe <topic>`, which
// deploy/security/make-pki turns into one signed permissions document per identity.
#include <cstring>
#include <iostream>

#include "rigger/protocol/access.hpp"
#include "rigger/protocol/catalog.hpp"

int main(int argc, char** argv) {
  if (argc == 1) {
    std::cout << rigger::protocol::catalog_markdown();
    return 0;
  }
  if (argc == 2 && std::strcmp(argv[1], "--permissions") == 0) {
    std::cout << rigger::protocol::access_table_lines();
    return 0;
  }
  std::cerr << "usage: rigger-topic-catalog [--permissions]\n"
               "  (no option)    the topic reference, docs/topics.md\n"
               "  --permissions  who may publish and subscribe to what, one line per grant:\n"
               "                 <identity> publish|subscribe <topic> (input of deploy/security/make-pki)\n";
  return 2;
}
