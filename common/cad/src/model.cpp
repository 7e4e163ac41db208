#include "rigger/cad/model.hpp"

#include "step_io.hpp"

#include <BRepCheck_Analyzer.hxx>
#include <BRep_Tool.hxx>
#include <BinTools.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Shell.hxx>
#include <TopoDS_Solid.hxx>

#include <fstream>
#include <sstream>

namespace rigger::cad {

std::string_view to_string(ErrorCode code) {
  switch (code) {
    case ErrorCode::kFileNotFound: return "CAD_FILE_NOT_FOUND";
    case ErrorCode::kTooLarge: return "CAD_TOO_LARGE";
    case ErrorCode::kEmpty: return "CAD_EMPTY";
    case ErrorCode::kNotStep: return "CAD_NOT_STEP";
    case ErrorCode::kNoGeometry: return "CAD_NO_GEOMETRY";
    case ErrorCode::kTooDeep: return "CAD_TOO_DEEP";
    case ErrorCode::kTimeout: return "CAD_TIMEOUT";
    case ErrorCode::kCrashed: return "CAD_READER_CRASHED";
    case ErrorCode::kWriteFailed: return "CAD_WRITE_FAILED";
    case ErrorCode::kBadReference: return "CAD_BAD_REFERENCE";
    case ErrorCode::kStaleReference: return "CAD_STALE_REFERENCE";
    case ErrorCode::kNotAFrame: return "CAD_NOT_A_FRAME";
    case ErrorCode::kNoUnits: return "CAD_NO_UNITS";
  }
  return "CAD_ERROR";
}

Model::Model(TopoDS_Shape shape_m, ProductNode product, std::string sha256, std::string source)
    : shape_(std::move(shape_m)), product_(std::move(product)), sha256_(std::move(sha256)), source_(std::move(source)) {}

namespace detail {

std::string read_bounded(const std::filesystem::path& path, const ReadLimits& limits) {
  std::error_code error;
  const auto size = std::filesystem::file_size(path, error);
  if (error) {
    throw CadError(ErrorCode::kFileNotFound, "cannot read STEP file " + path.string() + ": " + error.message());
  }
  if (size > limits.max_bytes) {
    throw CadError(ErrorCode::kTooLarge, "STEP file " + path.string() + " has " + std::to_string(size) +
                                             " bytes, more than the limit of " + std::to_string(limits.max_bytes));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw CadError(ErrorCode::kFileNotFound, "cannot open STEP file " + path.string());
  }
  std::string bytes(static_cast<std::size_t>(size), '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(size));
  if (static_cast<std::uintmax_t>(in.gcount()) != size) {
    throw CadError(ErrorCode::kFileNotFound, "STEP file " + path.string() + " changed while being read");
  }
  return bytes;
}

}  // namespace detail

void detail::check_step_bytes(std::string_view bytes, const std::string& source, const ReadLimits& limits) {
  if (bytes.empty()) {
    throw CadError(ErrorCode::kEmpty, "STEP input " + source + " is empty");
  }
  if (bytes.size() > limits.max_bytes) {
    throw CadError(ErrorCode::kTooLarge, "STEP input " + source + " has " + std::to_string(bytes.size()) +
                                             " bytes, more than the limit of " + std::to_string(limits.max_bytes));
  }
  // Cheap checks before OCCT sees the bytes: ISO 10303-21 starts with its magic line.
  const auto start = bytes.find_first_not_of(" \t\r\n");
  if (start == std::string_view::npos || bytes.compare(start, 13, "ISO-10303-21;") != 0) {
    throw CadError(ErrorCode::kNotStep,
                   "STEP input " + source + " does not start with 'ISO-10303-21;': not a STEP file");
  }
  if (bytes.find('\0') != std::string_view::npos) {
    throw CadError(ErrorCode::kNotStep, "STEP input " + source + " holds a NUL byte at offset " +
                                            std::to_string(bytes.find('\0')) + ": not a text STEP file");
  }
}

Model read_step_bytes(std::string_view bytes, const std::string& source, const ReadLimits& limits) {
  detail::check_step_bytes(bytes, source, limits);
  detail::StepContent content = limits.isolate ? detail::read_step_isolated(bytes, source, limits)
                                               : detail::read_step_in_process(bytes, source, limits);
  return Model(std::move(content.shape_m), std::move(content.product), sha256_hex(bytes), source);
}

Model read_step_file(const std::filesystem::path& path, const ReadLimits& limits) {
  const std::string bytes = detail::read_bounded(path, limits);
  return read_step_bytes(bytes, path.string(), limits);
}

Model model_from_shape(const TopoDS_Shape& shape_m, const std::string& name) {
  std::ostringstream out;
  BinTools::Write(shape_m, out);
  ProductNode product;
  product.name = name;
  return Model(shape_m, std::move(product), sha256_hex(out.str()), name);
}

std::string solid_problem(const Model& model) {
  int index = 0;
  for (TopExp_Explorer solids(model.shape(), TopAbs_SOLID); solids.More(); solids.Next(), ++index) {
    const TopoDS_Solid& solid = TopoDS::Solid(solids.Current());
    bool any_shell = false;
    bool closed = true;
    for (TopExp_Explorer shells(solid, TopAbs_SHELL); shells.More() && closed; shells.Next()) {
      any_shell = true;
      closed = BRep_Tool::IsClosed(TopoDS::Shell(shells.Current()));
    }
    if (!any_shell || !closed || !BRepCheck_Analyzer(solid).IsValid())
      return "solid " + std::to_string(index) + " is not closed (or not a valid solid)";
  }
  return index == 0 ? "no solid (faces or shells only)" : "";
}

}  // namespace rigger::cad
