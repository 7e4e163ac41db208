// rigger-performance-table: docs/performance.md from the benches' results (test/bench/run calls it).
//   rigger-performance-table FOLDER              prints the page for FOLDER/*.json
//   rigger-performance-table --convert IN OUT    turns Google Benchmark's --benchmark_out JSON into a result
#include <fstream>
#include <iostream>
#include <regex>
#include <sstream>
#include <string>

#include "rigger/performance/results.hpp"

namespace {

int convert(const std::string& in_path, const std::string& out_path) {
  std::ifstream in(in_path);
  std::ostringstream text;
  text << in.rdbuf();
  // Google Benchmark writes a counter's undefined aggregate (the cv of a counter that stayed 0) as a bare
  // NaN, which is not JSON: such a value becomes null, and a counter that is not a number is left out.
  static const std::regex kNotANumber(R"(:\s*-?(NaN|nan|inf|Infinity)\b)");
  const auto parsed = nlohmann::json::parse(std::regex_replace(text.str(), kNotANumber, ": null"), nullptr, false);
  if (parsed.is_discarded()) throw std::runtime_error(in_path + ": not valid JSON");
  const auto result = rigger::performance::result_from_json(parsed, in_path);
  std::ofstream out(out_path);
  out << rigger::performance::to_json(result).dump(2) << "\n";
  if (!out) throw std::runtime_error(out_path + ": cannot write");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc == 4 && std::string(argv[1]) == "--convert") return convert(argv[2], argv[3]);
    if (argc == 2 && argv[1][0] != '-') {
      std::cout << rigger::performance::performance_markdown(rigger::performance::read_results(argv[1]));
      return 0;
    }
  } catch (const std::exception& e) {
    std::cerr << "rigger-performance-table: " << e.what() << "\n";
    return 1;
  }
  std::cerr << "usage: rigger-performance-table RESULTS_FOLDER  (prints docs/performance.md)\n"
               "       rigger-performance-table --convert GOOGLE_BENCHMARK.json RESULT.json\n";
  return 2;
}
