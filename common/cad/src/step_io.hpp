#pragma once
// Reading STEP with OCCT, in this process or in a forked child; writing an XCAF document as STEP bytes.
// Internal to rigger_cad.

#include "rigger/cad/model.hpp"

#include <TDF_Label.hxx>
#include <TDocStd_Document.hxx>

#include <functional>
#include <string>
#include <string_view>

namespace rigger::cad::detail {

struct StepContent {
  TopoDS_Shape shape_m;
  ProductNode product;
};

/// Parses and transfers `bytes` with the XCAF reader in this process (lengths converted to metres).
StepContent read_step_in_process(std::string_view bytes, const std::string& source, const ReadLimits& limits);

/// The same in a forked child with a time and memory limit; the B-rep comes back in OCCT's binary format.
StepContent read_step_isolated(std::string_view bytes, const std::string& source, const ReadLimits& limits);

/// Runs `work` in a forked child with limits' time and memory bounds and returns what it returned; a
/// CadError it throws is thrown here, a crash or the timeout as kCrashed or kTimeout naming `source`.
std::string run_isolated(const std::string& source, const ReadLimits& limits, const std::function<std::string()>& work);

/// The bytes of a STEP file, refused (kFileNotFound, kTooLarge) before they are read when too large.
std::string read_bounded(const std::filesystem::path& path, const ReadLimits& limits);

/// Refuses (kEmpty, kTooLarge, kNotStep) bytes that are empty, too large or plainly not a text STEP file,
/// before OCCT sees them.
void check_step_bytes(std::string_view bytes, const std::string& source, const ReadLimits& limits);

/// A STEP input transferred into an XCAF document (lengths in the document's unit: `unit_m` metres
/// each), its length unit checked; the document is closed when this goes.
class StepDocument {
 public:
  StepDocument(std::string_view bytes, const std::string& source);
  ~StepDocument();
  StepDocument(const StepDocument&) = delete;
  StepDocument& operator=(const StepDocument&) = delete;

  const Handle(TDocStd_Document) & document() const { return document_; }
  double unit_m() const { return unit_m_; }
  /// The file's length unit as OCCT's writer names it (write.step.unit: "MM", "INCH", "M", ...).
  const std::string& write_unit() const { return write_unit_; }

 private:
  Handle(TDocStd_Document) document_;
  double unit_m_ = 0.001;
  std::string write_unit_ = "MM";
};

/// The name attribute of a label (UTF-8), "" without one.
std::string label_name(const TDF_Label& label);

/// `document` (its free shapes, names, the length unit set on it) as STEP AP214 bytes with lengths in
/// `unit` (write.step.unit) and a fixed header naming `file_name`: the same document gives the same bytes.
std::string write_step_bytes(const Handle(TDocStd_Document) & document, const std::string& file_name,
                             const std::string& unit);

}  // namespace rigger::cad::detail
