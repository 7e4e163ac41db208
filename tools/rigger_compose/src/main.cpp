#include "rigger/compose/commands.hpp"

int main(int argc, char** argv) { return rigger::compose::run_cli(argc, argv); }
