#include "step_io.hpp"

#include <BRepBuilderAPI_Transform.hxx>
#include <BRep_Builder.hxx>
#include <BinTools.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_Printer.hxx>
#include <STEPCAFControl_Reader.hxx>
#include <STEPCAFControl_Writer.hxx>
#include <STEPControl_Controller.hxx>
#include <XSControl_WorkSession.hxx>
#include <STEPControl_Reader.hxx>
#include <TColStd_SequenceOfAsciiString.hxx>
#include <Standard_Failure.hxx>
#include <Standard_OutOfMemory.hxx>
#include <TCollection_AsciiString.hxx>
#include <TDF_LabelSequence.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS_Compound.hxx>
#include <APIHeaderSection_MakeHeader.hxx>
#include <Interface_HArray1OfHAsciiString.hxx>
#include <StepData_Protocol.hxx>
#include <StepRepr_NextAssemblyUsageOccurrence.hxx>
#include <StepData_StepModel.hxx>
#include <StepData_StepWriter.hxx>
#include <TCollection_HAsciiString.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <istream>
#include <new>
#include <ostream>
#include <sstream>
#include <streambuf>
#include <utility>
#include <vector>

namespace rigger::cad::detail {
namespace {

constexpr int kMaxProducts = 100'000;

// write.step.unit's name of a length unit FileUnits() names ("MILLIMETRE", "INCH", ...); millimetres
// for one it does not know.
std::string writer_unit(std::string name) {
  for (char& c : name) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  const auto has = [&](const char* word) { return name.find(word) != std::string::npos; };
  if (has("INCH")) return "INCH";
  if (has("FOOT") || has("FEET")) return "FT";
  if (has("MILE")) return "MI";
  if (!has("METRE") && !has("METER")) return "MM";
  if (has("MILLI")) return "MM";
  if (has("CENTI")) return "CM";
  if (has("KILO")) return "KM";
  if (has("MICRO")) return "UM";
  if (has("NANO")) return "NM";
  return "M";
}

ProductNode product_node(const TDF_Label& label, int depth, const ReadLimits& limits, int& count, const std::string& source) {
  if (depth > limits.max_assembly_depth) {
    throw CadError(ErrorCode::kTooDeep, "STEP input " + source + ": the assembly is nested deeper than " +
                                            std::to_string(limits.max_assembly_depth) + " levels");
  }
  if (++count > kMaxProducts) {
    throw CadError(ErrorCode::kTooLarge,
                   "STEP input " + source + " has more than " + std::to_string(kMaxProducts) + " product instances");
  }
  ProductNode node;
  TDF_Label product = label;
  if (XCAFDoc_ShapeTool::IsReference(label)) {
    XCAFDoc_ShapeTool::GetReferredShape(label, product);
    node.instance = label_name(label);
  }
  node.name = label_name(product);
  if (node.name.empty()) {
    node.name = label_name(label);
  }
  if (XCAFDoc_ShapeTool::IsAssembly(product)) {
    node.assembly = true;
    TDF_LabelSequence components;
    XCAFDoc_ShapeTool::GetComponents(product, components, false);
    for (int i = 1; i <= components.Length(); ++i) {
      node.children.push_back(product_node(components.Value(i), depth + 1, limits, count, source));
    }
  }
  return node;
}

// Length-prefixed serialisation of the product tree for the pipe from the reader child.
void put_u32(std::string& out, std::uint32_t value) { out.append(reinterpret_cast<const char*>(&value), 4); }

std::uint32_t get_u32(std::string_view& in) {
  if (in.size() < 4) {
    throw std::runtime_error("truncated");
  }
  std::uint32_t value = 0;
  std::memcpy(&value, in.data(), 4);
  in.remove_prefix(4);
  return value;
}

void put_node(std::string& out, const ProductNode& node) {
  put_u32(out, static_cast<std::uint32_t>(node.name.size()));
  out += node.name;
  put_u32(out, static_cast<std::uint32_t>(node.instance.size()));
  out += node.instance;
  out += node.assembly ? '1' : '0';
  put_u32(out, static_cast<std::uint32_t>(node.children.size()));
  for (const auto& child : node.children) {
    put_node(out, child);
  }
}

ProductNode get_node(std::string_view& in) {
  ProductNode node;
  const auto length = get_u32(in);
  if (in.size() < length + 1) {
    throw std::runtime_error("truncated");
  }
  node.name = std::string(in.substr(0, length));
  in.remove_prefix(length);
  const auto instance = get_u32(in);
  if (in.size() < instance + 1) {
    throw std::runtime_error("truncated");
  }
  node.instance = std::string(in.substr(0, instance));
  node.assembly = in[instance] == '1';
  in.remove_prefix(instance + 1);
  const auto children = get_u32(in);
  for (std::uint32_t i = 0; i < children; ++i) {
    node.children.push_back(get_node(in));
  }
  return node;
}

// Streams over bytes already in memory, so that neither the STEP input (up to max_bytes) nor the B-rep
// coming back is copied into a string stream first.
class ViewBuffer : public std::streambuf {
 public:
  explicit ViewBuffer(std::string_view bytes) {
    char* begin = const_cast<char*>(bytes.data());  // only ever read: no put area
    setg(begin, begin, begin + bytes.size());
  }

 protected:
  pos_type seekoff(off_type offset, std::ios_base::seekdir way, std::ios_base::openmode which) override {
    if ((which & std::ios_base::in) == 0) {
      return pos_type(off_type(-1));
    }
    const off_type base = way == std::ios_base::beg   ? 0
                          : way == std::ios_base::cur ? gptr() - eback()
                                                      : egptr() - eback();
    const off_type at = base + offset;
    if (at < 0 || at > egptr() - eback()) {
      return pos_type(off_type(-1));
    }
    setg(eback(), eback() + at, egptr());
    return pos_type(at);
  }
  pos_type seekpos(pos_type position, std::ios_base::openmode which) override {
    return seekoff(off_type(position), std::ios_base::beg, which);
  }
};

// An output stream buffer that appends to a string: the child writes the B-rep behind the header of its
// answer without an intermediate copy.
class AppendBuffer : public std::streambuf {
 public:
  explicit AppendBuffer(std::string& out) : out_(out) {}

 protected:
  int_type overflow(int_type c) override {
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      out_ += traits_type::to_char_type(c);
    }
    return traits_type::not_eof(c);
  }
  std::streamsize xsputn(const char* data, std::streamsize count) override {
    out_.append(data, static_cast<std::size_t>(count));
    return count;
  }

 private:
  std::string& out_;
};

void write_all(int fd, std::string_view data) {
  while (!data.empty()) {
    const auto written = ::write(fd, data.data(), data.size());
    if (written < 0) {
      if (errno == EINTR) {
        continue;
      }
      return;
    }
    data.remove_prefix(static_cast<std::size_t>(written));
  }
}

}  // namespace

std::string label_name(const TDF_Label& label) {
  Handle(TDataStd_Name) name;
  if (label.FindAttribute(TDataStd_Name::GetID(), name)) {
    return TCollection_AsciiString(name->Get()).ToCString();  // UTF-8
  }
  return {};
}

StepDocument::StepDocument(std::string_view bytes, const std::string& source) {
  STEPCAFControl_Reader reader;
  reader.SetNameMode(true);
  reader.SetColorMode(false);
  reader.SetLayerMode(false);
  reader.SetPropsMode(false);
  reader.SetGDTMode(false);
  reader.SetMatMode(false);
  reader.SetViewMode(false);
  ViewBuffer buffer(bytes);
  std::istream in(&buffer);
  if (reader.ChangeReader().ReadStream(source.c_str(), in) != IFSelect_RetDone) {
    throw CadError(ErrorCode::kNotStep, "STEP input " + source + " could not be parsed (syntax errors or truncated)");
  }
  XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", document_);
  // The transfer runs in the document's default unit (millimetres): asking OCCT for metres makes its
  // shape healing three times slower (its tolerances are tuned for millimetres). Scaled after.
  if (!reader.Transfer(document_)) {
    XCAFApp_Application::GetApplication()->Close(document_);
    throw CadError(ErrorCode::kNotStep, "STEP input " + source + " holds no product OCCT can transfer");
  }
  // A length unit is part of every representation context STEP defines; a file without one leaves its
  // numbers to be guessed (OCCT would take millimetres), and a wrong guess is a part 25 or 1000 times off.
  TColStd_SequenceOfAsciiString length_units;
  TColStd_SequenceOfAsciiString angle_units;
  TColStd_SequenceOfAsciiString solid_angle_units;
  reader.ChangeReader().FileUnits(length_units, angle_units, solid_angle_units);
  const TCollection_AsciiString* unit = nullptr;  // OCCT lists an empty name for a context with other units only
  for (const TCollection_AsciiString& name : length_units) {
    if (unit == nullptr && !name.IsEmpty()) unit = &name;
  }
  if (unit == nullptr) {
    XCAFApp_Application::GetApplication()->Close(document_);
    throw CadError(ErrorCode::kNoUnits, "STEP input " + source +
                                            " declares no length unit (expected a LENGTH_UNIT in the "
                                            "GLOBAL_UNIT_ASSIGNED_CONTEXT of its geometric representation context)");
  }
  write_unit_ = writer_unit(unit->ToCString());
  if (!XCAFDoc_DocumentTool::GetLengthUnit(document_, unit_m_) || !(unit_m_ > 0)) {
    unit_m_ = 0.001;
  }
}

StepDocument::~StepDocument() { XCAFApp_Application::GetApplication()->Close(document_); }

StepContent read_step_in_process(std::string_view bytes, const std::string& source, const ReadLimits& limits) {
  try {
    const StepDocument read(bytes, source);
    Handle(XCAFDoc_ShapeTool) shapes = XCAFDoc_DocumentTool::ShapeTool(read.document()->Main());
    TDF_LabelSequence roots;
    shapes->GetFreeShapes(roots);
    StepContent content;
    int count = 0;
    if (roots.Length() == 1) {
      content.product = product_node(roots.Value(1), 0, limits, count, source);
      content.shape_m = XCAFDoc_ShapeTool::GetShape(roots.Value(1));
    } else {
      content.product.name = source;
      content.product.assembly = true;
      TopoDS_Compound compound;
      BRep_Builder builder;
      builder.MakeCompound(compound);
      for (int i = 1; i <= roots.Length(); ++i) {
        content.product.children.push_back(product_node(roots.Value(i), 1, limits, count, source));
        builder.Add(compound, XCAFDoc_ShapeTool::GetShape(roots.Value(i)));
      }
      content.shape_m = compound;
    }
    if (!content.shape_m.IsNull() && std::abs(read.unit_m() - 1.0) > 1e-12) {
      gp_Trsf scale;
      scale.SetScale(gp_Pnt(0, 0, 0), read.unit_m());
      content.shape_m = BRepBuilderAPI_Transform(content.shape_m, scale, true).Shape();
    }
    if (content.shape_m.IsNull() || !TopExp_Explorer(content.shape_m, TopAbs_FACE).More()) {
      throw CadError(ErrorCode::kNoGeometry, "STEP input " + source + " holds no face (no geometry)");
    }
    return content;
  } catch (const Standard_OutOfMemory&) {
    throw CadError(ErrorCode::kCrashed, "reading STEP input " + source + " needed more than " +
                                            std::to_string(limits.max_memory_bytes >> 20) + " MiB of memory");
  } catch (const Standard_Failure& failure) {
    throw CadError(ErrorCode::kNotStep, "OCCT failed on STEP input " + source + ": " +
                                            failure.DynamicType()->Name() + " " + failure.GetMessageString());
  }
}

std::string run_isolated(const std::string& source, const ReadLimits& limits, const std::function<std::string()>& work) {
  int fds[2];
  if (::pipe(fds) != 0) {
    throw CadError(ErrorCode::kCrashed, std::string("cannot start the STEP reader: pipe: ") + std::strerror(errno));
  }
#ifdef F_SETPIPE_SZ
  // A pipe as large as Linux allows unprivileged (1 MiB): the child writes a B-rep of that size at once
  // instead of waiting for the parent every 64 KiB. Best effort.
  ::fcntl(fds[1], F_SETPIPE_SZ, 1 << 20);
#endif
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    throw CadError(ErrorCode::kCrashed, std::string("cannot start the STEP reader: fork: ") + std::strerror(errno));
  }
  if (pid == 0) {
    // The child: work, send the result (or the error) through the pipe, and leave without running the
    // parent's atexit handlers or destructors.
    ::close(fds[0]);
    const rlimit memory{limits.max_memory_bytes, limits.max_memory_bytes};
    ::setrlimit(RLIMIT_AS, &memory);
    std::string message;
    try {
      message = "O" + work();
    } catch (const CadError& error) {
      message = "E";
      put_u32(message, static_cast<std::uint32_t>(error.code()));
      message += error.what();
    } catch (const std::bad_alloc&) {
      message = "E";
      put_u32(message, static_cast<std::uint32_t>(ErrorCode::kCrashed));
      message += "reading STEP input " + source + " needed more than " +
                 std::to_string(limits.max_memory_bytes >> 20) + " MiB of memory";
    } catch (const std::exception& error) {
      message = "E";
      put_u32(message, static_cast<std::uint32_t>(ErrorCode::kNotStep));
      message += "reading STEP input " + source + " failed: " + error.what();
    }
    write_all(fds[1], message);
    ::close(fds[1]);
    ::_exit(0);
  }
  ::close(fds[1]);
  std::string answer;
  const auto deadline = std::chrono::steady_clock::now() + limits.timeout;
  bool timed_out = false;
  constexpr std::size_t kChunk = 1 << 20;
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      timed_out = true;
      break;
    }
    pollfd poll_fd{fds[0], POLLIN, 0};
    const int ready = ::poll(&poll_fd, 1, static_cast<int>(std::min<long long>(left.count(), 1000)));
    if (ready < 0 && errno != EINTR) {
      break;
    }
    if (ready <= 0) {
      continue;
    }
    const std::size_t size = answer.size();
    answer.resize(size + kChunk);  // read straight into the answer
    const auto got = ::read(fds[0], answer.data() + size, kChunk);
    answer.resize(size + static_cast<std::size_t>(std::max<ssize_t>(got, 0)));
    if (got < 0 && errno == EINTR) {
      continue;
    }
    if (got <= 0) {
      break;
    }
  }
  ::close(fds[0]);
  if (timed_out) {
    ::kill(pid, SIGKILL);
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (timed_out) {
    throw CadError(ErrorCode::kTimeout, "reading STEP input " + source + " took longer than " +
                                            std::to_string(limits.timeout.count()) + " ms: the reader was stopped");
  }
  if (WIFSIGNALED(status)) {
    throw CadError(ErrorCode::kCrashed, "the STEP reader died on input " + source + " (signal " +
                                            std::to_string(WTERMSIG(status)) + ", " + strsignal(WTERMSIG(status)) +
                                            "): the file is malformed or hostile");
  }
  if (answer.empty()) {
    throw CadError(ErrorCode::kCrashed, "the STEP reader exited on input " + source + " without an answer (status " +
                                            std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")");
  }
  if (answer.front() == 'E') {
    std::string_view in(answer);
    in.remove_prefix(1);
    ErrorCode code = ErrorCode::kCrashed;
    try {
      code = static_cast<ErrorCode>(get_u32(in));
    } catch (const std::exception&) {
      throw CadError(ErrorCode::kCrashed, "the STEP reader's answer for " + source + " is truncated");
    }
    throw CadError(code, std::string(in));
  }
  answer.erase(0, 1);
  return answer;
}

StepContent read_step_isolated(std::string_view bytes, const std::string& source, const ReadLimits& limits) {
  const std::string answer = run_isolated(source, limits, [&] {
    const StepContent content = read_step_in_process(bytes, source, limits);
    std::string message;
    std::string tree;
    put_node(tree, content.product);
    put_u32(message, static_cast<std::uint32_t>(tree.size()));
    message += tree;
    AppendBuffer shape(message);
    std::ostream out(&shape);
    BinTools::Write(content.shape_m, out);
    return message;
  });
  std::string_view in(answer);
  try {
    const auto tree_size = get_u32(in);
    std::string_view tree = in.substr(0, tree_size);
    in.remove_prefix(std::min<std::size_t>(tree_size, in.size()));
    StepContent content;
    content.product = get_node(tree);
    ViewBuffer buffer(in);
    std::istream shape(&buffer);
    BinTools::Read(content.shape_m, shape);
    return content;
  } catch (const std::exception& error) {
    throw CadError(ErrorCode::kCrashed, "the STEP reader's answer for " + source + " is truncated: " + error.what());
  } catch (const Standard_Failure& failure) {
    throw CadError(ErrorCode::kCrashed, "the STEP reader's answer for " + source + " is unreadable: " +
                                            failure.GetMessageString());
  }
}

std::string write_step_bytes(const Handle(TDocStd_Document) & document, const std::string& file_name,
                             const std::string& unit) {
  // The writer prints its statistics through OCCT's default printers (stdout: the service's log): only
  // failures while it runs.
  struct Quiet {
    std::vector<std::pair<Handle(Message_Printer), Message_Gravity>> levels;
    Quiet() {
      for (const Handle(Message_Printer)& printer : Message::DefaultMessenger()->Printers()) {
        levels.emplace_back(printer, printer->GetTraceLevel());
        printer->SetTraceLevel(Message_Fail);
      }
    }
    ~Quiet() {
      for (auto& [printer, level] : levels) printer->SetTraceLevel(level);
    }
  } quiet;
  // The unit before the writer: it scales by the unit set when it is made and names the one set when it
  // transfers. Its parameters exist once the STEP controller is initialised.
  STEPControl_Controller::Init();
  if (!Interface_Static::SetCVal("write.step.unit", unit.c_str())) {
    throw CadError(ErrorCode::kWriteFailed, "cannot write " + file_name + " in " + unit + ": not a unit OCCT writes");
  }
  STEPCAFControl_Writer writer;
  writer.SetNameMode(true);
  writer.SetColorMode(false);
  writer.SetLayerMode(false);
  writer.SetPropsMode(false);
  writer.SetMaterialMode(false);
  writer.SetDimTolMode(false);
  if (!writer.Transfer(document, STEPControl_AsIs)) {
    throw CadError(ErrorCode::kWriteFailed, "cannot write " + file_name + " as STEP: OCCT did not transfer it");
  }
  // The header the writer stamps with the time and the user: fixed, so that the same document gives the
  // same bytes. Then written to memory (the model as it is, without the session's file modifiers).
  const Handle(StepData_StepModel) model = writer.ChangeWriter().Model();
  // OCCT numbers assembly usages from a counter of the process: numbered here in the file's order.
  int usage = 0;
  for (int i = 1; i <= model->NbEntities(); ++i) {
    const auto nauo = Handle(StepRepr_NextAssemblyUsageOccurrence)::DownCast(model->Value(i));
    if (!nauo.IsNull()) nauo->SetId(new TCollection_HAsciiString(++usage));
  }
  APIHeaderSection_MakeHeader header(model);
  const auto one = [](const char* value) {
    Handle(Interface_HArray1OfHAsciiString) values = new Interface_HArray1OfHAsciiString(1, 1);
    values->SetValue(1, new TCollection_HAsciiString(value));
    return values;
  };
  header.SetName(new TCollection_HAsciiString(file_name.c_str()));
  header.SetTimeStamp(new TCollection_HAsciiString("2000-01-01T00:00:00"));
  header.SetAuthor(one("rigger"));
  header.SetOrganization(one(""));
  header.SetOriginatingSystem(new TCollection_HAsciiString("rigger"));
  header.SetAuthorisation(new TCollection_HAsciiString(""));
  const Handle(StepData_Protocol) protocol = Handle(StepData_Protocol)::DownCast(writer.ChangeWriter().WS()->Protocol());
  if (protocol.IsNull()) throw CadError(ErrorCode::kWriteFailed, "cannot write " + file_name + " as STEP: no STEP protocol");
  StepData_StepWriter out(model);
  out.SendModel(protocol);
  std::ostringstream text;
  if (!out.Print(text)) {
    throw CadError(ErrorCode::kWriteFailed, "cannot write " + file_name + " as STEP");
  }
  return text.str();
}

}  // namespace rigger::cad::detail

namespace rigger::cad {

void write_step(const TopoDS_Shape& shape_m, const std::string& product, const std::filesystem::path& path) {
  try {
    Handle(TDocStd_Document) document;
    XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", document);
    XCAFDoc_DocumentTool::SetLengthUnit(document, 1.0);
    Handle(XCAFDoc_ShapeTool) shapes = XCAFDoc_DocumentTool::ShapeTool(document->Main());
    const TDF_Label label = shapes->AddShape(shape_m, false);
    TDataStd_Name::Set(label, TCollection_ExtendedString(product.c_str(), true));
    STEPCAFControl_Writer writer;
    Interface_Static::SetCVal("write.step.unit", "MM");
    Interface_Static::SetCVal("write.step.product.name", product.c_str());
    if (!writer.Transfer(document, STEPControl_AsIs) || writer.Write(path.c_str()) != IFSelect_RetDone) {
      throw CadError(ErrorCode::kWriteFailed, "cannot write STEP file " + path.string());
    }
    XCAFApp_Application::GetApplication()->Close(document);
  } catch (const Standard_Failure& failure) {
    throw CadError(ErrorCode::kWriteFailed,
                   "OCCT failed writing STEP file " + path.string() + ": " + failure.GetMessageString());
  }
}

}  // namespace rigger::cad
