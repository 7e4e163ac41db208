// rigger-skill-catalog: prints the skill library (`library`) or the skill reference (`markdown`) generated
// from the descriptions built into rigger. tools/update-skill-library writes both into the repository.
#include <cstring>
#include <iostream>

#include "catalog.hpp"

int main(int argc, char** argv) {
  if (argc == 2 && std::strcmp(argv[1], "library") == 0) {
    std::cout << rigger::catalog::library_json().dump(2) << "\n";
    return 0;
  }
  if (argc == 2 && std::strcmp(argv[1], "markdown") == 0) {
    std::cout << rigger::catalog::reference_markdown(rigger::catalog::library_json());
    return 0;
  }
  std::cerr << "usage: rigger-skill-catalog library|markdown\n";
  return 2;
}
