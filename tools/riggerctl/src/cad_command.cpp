// `riggerctl cad inspect|frame|extract FILE`: reads a STEP file with rigger's CAD library (in a child
// process, bounded) and prints its product tree and features, the frame a pick rule makes, or writes one
// node of its product tree as a STEP file of its own. Offline: no DDS.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "rigger/base/sha256.hpp"
#include "rigger/base/text.hpp"
#include "rigger/cad/assembly.hpp"
#include "rigger/cad/cad_json.hpp"
#include "rigger/cad/frames.hpp"

namespace rigger::ctl {
namespace {

constexpr int kExitCadError = 1;
constexpr int kExitUsage = 2;

struct CadArgs {
  std::string file;
  bool json = false;
  bool entities = false;
  std::string point;
  std::string edges;
  int face = -1;
  int hole = -1;
  std::string node;
  std::string output;
};

std::string vec_text(const Eigen::Vector3d& v) {
  return "(" + number_text(v.x()) + ", " + number_text(v.y()) + ", " + number_text(v.z()) + ")";
}

// Each node with its path from the root ("0/1"), as `cad extract --node` takes it.
void print_tree(const cad::ProductNode& node, const cad::NodePath& path) {
  const bool instance = !node.instance.empty() && node.instance != node.name;
  const std::string at = path.empty() ? "" : "  [" + cad::to_string(path) + "]";
  std::printf("%*s%s%s%s%s%s\n", 2 * static_cast<int>(path.size() + 1), "", node.name.empty() ? "(unnamed)" : node.name.c_str(),
              node.assembly ? " [assembly]" : "", instance ? " instance " : "", instance ? node.instance.c_str() : "",
              at.c_str());
  for (std::size_t i = 0; i < node.children.size(); ++i) {
    cad::NodePath child = path;
    child.push_back(static_cast<int>(i));
    print_tree(node.children[i], child);
  }
}

// "0/1": the component indices from the root; nullopt when the text is not that.
std::optional<cad::NodePath> parse_node_path(const std::string& text) {
  cad::NodePath path;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, '/')) {
    if (item.empty() || item.size() > 6 || item.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
    path.push_back(std::stoi(item));
  }
  if (path.empty() || text.back() == '/') return std::nullopt;
  return path;
}

bool parse_numbers(const std::string& text, std::size_t count, std::vector<double>& out) {
  out.clear();
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    std::size_t used = 0;
    try {
      out.push_back(std::stod(item, &used));
    } catch (const std::exception&) {
      return false;
    }
    if (used != item.size()) {
      return false;
    }
  }
  return out.size() == count;
}

// The B-spline faces and edges classified as planes, cylinders, lines or circles, by type.
void print_recognised(const cad::Features& features) {
  std::map<std::string, std::vector<int>> faces, edges;
  for (const auto& face : features.faces) {
    if (face.recognised) faces[face.signature.type].push_back(face.index);
  }
  for (const auto& edge : features.edges) {
    if (edge.recognised) edges[edge.signature.type].push_back(edge.index);
  }
  if (faces.empty() && edges.empty()) {
    return;
  }
  std::printf("\nrecognised from B-spline (within 0.01 mm):\n");
  for (const auto& [kind, by_type] : {std::pair{"face", &faces}, std::pair{"edge", &edges}}) {
    for (const auto& [type, indices] : *by_type) {
      std::printf("  %s %ss (%zu):", type.c_str(), kind, indices.size());
      for (int index : indices) {
        std::printf(" %d", index);
      }
      std::printf("\n");
    }
  }
}

int inspect(const CadArgs& args) {
  const cad::Model model = cad::read_step_file(args.file);
  const cad::Features features = cad::classify(model);
  if (args.json) {
    nlohmann::json json = cad::features_json(features, args.entities);
    json["file"] = args.file;
    json["product"] = cad::to_json(model.product());
    std::cout << json.dump(2) << "\n";
    return 0;
  }
  std::printf("%s\nsha256 %s\n\nproduct tree:\n", args.file.c_str(), model.sha256().c_str());
  print_tree(model.product(), {});
  const auto counts = cad::features_json(features, false)["counts"];
  std::printf("\nfeatures:\n");
  for (const auto& [kind, count] : counts.items()) {
    std::printf("  %-18s %s\n", kind.c_str(), count.dump().c_str());
  }
  print_recognised(features);
  if (!features.holes.empty()) {
    std::printf("\nholes (m):\n");
  }
  for (const auto& hole : features.holes) {
    std::printf("  hole %d: diameter %s, depth %s, %s, entry %s, axis %s, faces", hole.index,
                number_text(hole.diameter_m).c_str(), number_text(hole.depth_m).c_str(),
                hole.through ? "through" : "blind", vec_text(hole.entry_m).c_str(), vec_text(hole.axis).c_str());
    for (int face : hole.faces) {
      std::printf(" %d", face);
    }
    std::printf("\n");
  }
  return 0;
}

int frame(const CadArgs& args) {
  const int rules = (!args.edges.empty() ? 1 : 0) + (args.face >= 0 ? 1 : 0) + (args.hole >= 0 ? 1 : 0);
  if (rules != 1) {
    std::fprintf(stderr, "riggerctl: cad frame: give exactly one of --edges E1,E2 (with --point), --face F (with --point), --hole H\n");
    return kExitUsage;
  }
  std::vector<double> point;
  if ((!args.edges.empty() || args.face >= 0) && !parse_numbers(args.point, 3, point)) {
    std::fprintf(stderr, "riggerctl: cad frame: --point must be x,y,z in metres, got \"%s\"\n", args.point.c_str());
    return kExitUsage;
  }
  std::vector<double> edges;
  if (!args.edges.empty() && !parse_numbers(args.edges, 2, edges)) {
    std::fprintf(stderr, "riggerctl: cad frame: --edges must be two edge indices E1,E2, got \"%s\"\n", args.edges.c_str());
    return kExitUsage;
  }
  const cad::Model model = cad::read_step_file(args.file);
  const cad::Features features = cad::classify(model);
  Eigen::Isometry3d pose;
  std::string rule;
  if (!edges.empty()) {
    pose = cad::frame_from_edges(features, {point[0], point[1], point[2]}, static_cast<int>(edges[0]), static_cast<int>(edges[1]));
    rule = "point and edges " + args.edges;
  } else if (args.face >= 0) {
    pose = cad::frame_from_face(model, features, args.face, {point[0], point[1], point[2]});
    rule = "face " + std::to_string(args.face);
  } else {
    pose = cad::frame_from_hole(features, args.hole);
    rule = "hole " + std::to_string(args.hole);
  }
  if (args.json) {
    nlohmann::json json{{"file", args.file}, {"model_sha256", model.sha256()}, {"rule", rule}, {"frame", cad::to_json(pose)}};
    std::cout << json.dump(2) << "\n";
    return 0;
  }
  std::printf("frame from %s of %s (model frame, m):\n  origin %s\n  x %s\n  y %s\n  z %s\n", rule.c_str(),
              args.file.c_str(), vec_text(pose.translation()).c_str(), vec_text(pose.linear().col(0)).c_str(),
              vec_text(pose.linear().col(1)).c_str(), vec_text(pose.linear().col(2)).c_str());
  return 0;
}

// One node of the file's product tree (a part or a sub-assembly) as a STEP file of its own, in its own
// frame, as the Planner adds a node to the cell.
int extract(const CadArgs& args) {
  const auto path = parse_node_path(args.node);
  if (!path) {
    std::fprintf(stderr, "riggerctl: cad extract: --node must be the component indices from the root, e.g. 0/1 (as "
                         "`riggerctl cad inspect` shows them), got \"%s\"\n", args.node.c_str());
    return kExitUsage;
  }
  std::error_code error;
  if (std::filesystem::exists(args.output, error)) {
    std::fprintf(stderr, "riggerctl: cad extract: %s exists: not overwritten (remove it or name another)\n", args.output.c_str());
    return kExitUsage;
  }
  const cad::ExtractedNode node = cad::extract_step_node(std::filesystem::path(args.file), *path);
  std::ofstream out(args.output, std::ios::binary);
  out.write(node.step.data(), static_cast<std::streamsize>(node.step.size()));
  out.close();
  if (!out) {
    std::fprintf(stderr, "riggerctl: cad extract: could not write %s\n", args.output.c_str());
    std::filesystem::remove(args.output, error);
    return kExitCadError;
  }
  const Eigen::Isometry3d& at = node.pose_in_file;
  std::printf("node %s ('%s'%s%s) of %s written to %s\n  %zu bytes, sha256 %s\n  placed in the file at %s m, "
              "x %s, z %s\n",
              cad::to_string(*path).c_str(), node.name.c_str(), node.instance.empty() ? "" : ", instance ",
              node.instance.c_str(), args.file.c_str(), args.output.c_str(), node.step.size(),
              sha256_hex(node.step).c_str(), vec_text(at.translation()).c_str(), vec_text(at.linear().col(0)).c_str(),
              vec_text(at.linear().col(2)).c_str());
  return 0;
}

int guarded(int (*command)(const CadArgs&), const CadArgs& args) {
  try {
    return command(args);
  } catch (const cad::CadError& error) {
    std::fprintf(stderr, "riggerctl: cad: %s: %s\n", std::string(cad::to_string(error.code())).c_str(), error.what());
    return kExitCadError;
  }
}

}  // namespace

void add_cad_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<CadArgs>();
  auto* cad = app.add_subcommand("cad", "Read a STEP file: its product tree, features and frames from picks (offline)");
  cad->require_subcommand(1);
  auto* inspect_cmd = cad->add_subcommand("inspect", "Product tree, feature counts and every hole (axis, diameter, entry, depth)");
  inspect_cmd->add_option("file", args->file, "STEP file")->required();
  inspect_cmd->add_flag("--json", args->json, "One JSON document (docs/cad.md)");
  inspect_cmd->add_flag("--entities", args->entities, "With --json: every face, edge and vertex with its reference signature");
  inspect_cmd->callback([args, &exit_code] { exit_code = guarded(inspect, *args); });
  auto* frame_cmd = cad->add_subcommand("frame", "A frame from picks: --point + --edges (the paper's rule), --face + --point, or --hole");
  frame_cmd->add_option("file", args->file, "STEP file")->required();
  frame_cmd->add_option("--point", args->point, "x,y,z in metres, in the model's frame");
  frame_cmd->add_option("--edges", args->edges, "E1,E2: edge indices (x along E1, y along E2)");
  frame_cmd->add_option("--face", args->face, "face index (z along its outward normal at --point)");
  frame_cmd->add_option("--hole", args->hole, "hole index (z along its axis, origin at its entry)");
  frame_cmd->add_flag("--json", args->json, "One JSON document");
  frame_cmd->callback([args, &exit_code] { exit_code = guarded(frame, *args); });
  auto* extract_cmd = cad->add_subcommand("extract", "One node of the product tree (a part or sub-assembly) as a STEP file of its own");
  extract_cmd->add_option("file", args->file, "STEP file")->required();
  extract_cmd->add_option("--node", args->node, "the node's path from the root, e.g. 0/1 (cad inspect shows each node's)")->required();
  extract_cmd->add_option("--output,-o", args->output, "the STEP file to write (not overwritten if it exists)")->required();
  extract_cmd->callback([args, &exit_code] { exit_code = guarded(extract, *args); });
}

}  // namespace rigger::ctl
