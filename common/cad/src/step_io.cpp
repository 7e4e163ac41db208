#include "step_io.hpp"

#include <BRepBuilderAPI_Transform.hxx>
#include <BRep_Builder.hxx>
#include <BinTools.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <Interface_Static.hxx>
#include <STEPCAFControl_Reader.hxx>
#include <STEPCAFControl_Writer.hxx>
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
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <istream>
#include <new>
#include <ostream>
#include <streambuf>

namespace rigger::cad::detail {
namespace {

constexpr int kMaxProducts = 100'000;

std::string label_name(const TDF_Label& label) {
  Handle(TDataStd_Name) name;
  if (label.FindAttribute(TDataStd_Name::GetID(), name)) {
    return TCollection_AsciiString(name->Get()).ToCString();  // UTF-8
  }
  return {};
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
  node.assembly = in[length] == '1';
  in.remove_prefix(length + 1);
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

StepContent read_step_in_process(std::string_view bytes, const std::string& source, const ReadLimits& limits) {
  try {
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
    Handle(TDocStd_Document) document;
    XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", document);
    // The transfer runs in the document's default unit (millimetres): asking OCCT for metres makes its
    // shape healing three times slower (its tolerances are tuned for millimetres). Scaled after.
    if (!reader.Transfer(document)) {
      throw CadError(ErrorCode::kNotStep, "STEP input " + source + " holds no product OCCT can transfer");
    }
    // A length unit is part of every representation context STEP defines; a file without one leaves its
    // numbers to be guessed (OCCT would take millimetres), and a wrong guess is a part 25 or 1000 times off.
    TColStd_SequenceOfAsciiString length_units;
    TColStd_SequenceOfAsciiString angle_units;
    TColStd_SequenceOfAsciiString solid_angle_units;
    reader.ChangeReader().FileUnits(length_units, angle_units, solid_angle_units);
    bool has_length_unit = false;  // OCCT lists an empty name for a context with other units only
    for (const TCollection_AsciiString& name : length_units) has_length_unit = has_length_unit || !name.IsEmpty();
    if (!has_length_unit) {
      XCAFApp_Application::GetApplication()->Close(document);
      throw CadError(ErrorCode::kNoUnits, "STEP input " + source +
                                              " declares no length unit (expected a LENGTH_UNIT in the "
                                              "GLOBAL_UNIT_ASSIGNED_CONTEXT of its geometric representation context)");
    }
    Handle(XCAFDoc_ShapeTool) shapes = XCAFDoc_DocumentTool::ShapeTool(document->Main());
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
    double unit_m = 0.001;
    if (!XCAFDoc_DocumentTool::GetLengthUnit(document, unit_m) || !(unit_m > 0)) {
      unit_m = 0.001;
    }
    XCAFApp_Application::GetApplication()->Close(document);
    if (!content.shape_m.IsNull() && std::abs(unit_m - 1.0) > 1e-12) {
      gp_Trsf scale;
      scale.SetScale(gp_Pnt(0, 0, 0), unit_m);
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

StepContent read_step_isolated(std::string_view bytes, const std::string& source, const ReadLimits& limits) {
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
    // The child: read, send the result (or the error) through the pipe, and leave without running the
    // parent's atexit handlers or destructors.
    ::close(fds[0]);
    const rlimit memory{limits.max_memory_bytes, limits.max_memory_bytes};
    ::setrlimit(RLIMIT_AS, &memory);
    std::string message;
    try {
      const StepContent content = read_step_in_process(bytes, source, limits);
      message = "O";
      std::string tree;
      put_node(tree, content.product);
      put_u32(message, static_cast<std::uint32_t>(tree.size()));
      message += tree;
      AppendBuffer shape(message);
      std::ostream out(&shape);
      BinTools::Write(content.shape_m, out);
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
  std::string_view in(answer);
  const char kind = in.front();
  in.remove_prefix(1);
  try {
    if (kind == 'E') {
      const auto code = static_cast<ErrorCode>(get_u32(in));
      throw CadError(code, std::string(in));
    }
    const auto tree_size = get_u32(in);
    std::string_view tree = in.substr(0, tree_size);
    in.remove_prefix(std::min<std::size_t>(tree_size, in.size()));
    StepContent content;
    content.product = get_node(tree);
    ViewBuffer buffer(in);
    std::istream shape(&buffer);
    BinTools::Read(content.shape_m, shape);
    return content;
  } catch (const CadError&) {
    throw;
  } catch (const std::exception& error) {
    throw CadError(ErrorCode::kCrashed, "the STEP reader's answer for " + source + " is truncated: " + error.what());
  } catch (const Standard_Failure& failure) {
    throw CadError(ErrorCode::kCrashed, "the STEP reader's answer for " + source + " is unreadable: " +
                                            failure.GetMessageString());
  }
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
