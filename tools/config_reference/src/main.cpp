// rigger-config-reference: prints docs/config-reference.md, generated from the services' settings tables
// (tools/update-config-reference writes it).
#include <iostream>

#include "reference.hpp"

int main(int argc, char**) {
  if (argc != 1) {
    std::cerr << "usage: rigger-config-reference  (prints docs/config-reference.md)\n";
    return 2;
  }
  std::cout << rigger::config_reference::reference_markdown();
  return 0;
}
