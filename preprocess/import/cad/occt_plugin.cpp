// nave's CAD plugin (libnave_cad.so): the implementation of preprocess/import/cad_plugin.h with
// Open CASCADE 7.6. The file is read into an XCAF document (shapes with their assembly structure,
// names, colours and layers), converted to metres by the reader itself, then walked leaf by leaf
// (XCAFPrs_DocumentExplorer: every placed part with its accumulated transform and inherited
// style); each part is tessellated by BRepMesh and its faces read with RWMesh_FaceIterator, which
// applies the placement, the faces' orientation and their own colours.

#include <BRepBndLib.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <IGESCAFControl_Reader.hxx>
#include <IGESData_GlobalSection.hxx>
#include <IGESData_IGESModel.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_Printer.hxx>
#include <Message_PrinterOStream.hxx>
#include <RWMesh_FaceIterator.hxx>
#include <STEPCAFControl_Reader.hxx>
#include <STEPControl_Reader.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_HSequenceOfExtendedString.hxx>
#include <TColStd_SequenceOfAsciiString.hxx>
#include <TDF_LabelSequence.hxx>
#include <TDF_Tool.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_LayerTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <XCAFPrs_DocumentExplorer.hxx>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <new>
#include <unordered_map>

#include "preprocess/import/cad_plugin.h"
#include "preprocess/import/file_extension.h"
#include "preprocess/import/material_table.h"

namespace nave::preprocess::cad {
namespace {

std::string Utf8(const TCollection_ExtendedString& s) {
    return TCollection_AsciiString(s, '?').ToCString();
}

std::string EntryOf(const TDF_Label& label) {
    TCollection_AsciiString entry;
    TDF_Tool::Entry(label, entry);
    return entry.ToCString();
}

// The name a label carries (TDataStd_Name), or empty.
std::string NameOf(const TDF_Label& label) {
    Handle(TDataStd_Name) name;
    if (label.IsNull() || !label.FindAttribute(TDataStd_Name::GetID(), name)) return {};
    return Utf8(name->Get());
}

// The first layer a label is on, or empty. A layer named by a bare number (a CAD system's default
// numbered level, such as the "256" of some translators) says less than the part's own name, so
// it is passed over.
std::string LayerOf(const Handle(XCAFDoc_LayerTool) & layers, const TDF_Label& label) {
    Handle(TColStd_HSequenceOfExtendedString) names;
    if (label.IsNull() || layers.IsNull() || !layers->GetLayers(label, names) || names.IsNull() ||
        names->IsEmpty()) {
        return {};
    }
    const std::string layer = Utf8(names->Value(1));
    const bool numbered = std::all_of(layer.begin(), layer.end(), [](char c) {
        return std::isdigit(static_cast<unsigned char>(c)) != 0;
    });
    return numbered ? std::string() : layer;
}

// Keeps what Open CASCADE reports as it reads (instead of printing it on nave's standard output),
// so that a refusal can say what the library found: the first failure or alarm ("Syntax error at
// line 3"...).
class MessageRecorder final : public Message_Printer {
  public:
    std::string FirstProblem() const { return first_problem_; }

  protected:
    void send(const TCollection_AsciiString& text, const Message_Gravity gravity) const override {
        if (gravity < Message_Alarm || !first_problem_.empty()) return;
        std::string line = text.ToCString();
        // Without the frame of stars Open CASCADE draws around its errors.
        const auto frame = [](char c) {
            return c == '*' || std::isspace(static_cast<unsigned char>(c)) != 0;
        };
        while (!line.empty() && frame(line.back())) line.pop_back();
        while (!line.empty() && frame(line.front())) line.erase(line.begin());
        if (line.size() > 300) line = line.substr(0, 300) + "...";
        first_problem_ = line;
    }

  private:
    mutable std::string first_problem_;
};

// The file read into a document, in metres, with what the reader said of its units.
struct ReadDocument {
    Handle(TDocStd_Document) doc;
    std::string format, file_unit;
};

// Both XCAF readers (STEP and IGES) carry names, colours and layers into the document when asked.
template <typename XcafReader>
void KeepNamesColoursAndLayers(XcafReader& reader) {
    reader.SetColorMode(true);
    reader.SetNameMode(true);
    reader.SetLayerMode(true);
}

StatusOr<ReadDocument> ReadIntoDocument(const std::filesystem::path& file,
                                        const MessageRecorder& recorder) {
    ReadDocument out;
    Handle(XCAFApp_Application) app = XCAFApp_Application::GetApplication();
    app->NewDocument("MDTV-XCAF", out.doc);
    // The readers convert every length into the document's unit: metres, as the store keeps.
    XCAFDoc_DocumentTool::SetLengthUnit(out.doc, 1.0);
    const std::string ext = LowerExtension(file);
    const bool step = ext == ".step" || ext == ".stp";
    out.format = step ? "STEP" : "IGES";
    IFSelect_ReturnStatus read_status = IFSelect_RetVoid;
    bool transferred = false;
    if (step) {
        STEPCAFControl_Reader reader;
        KeepNamesColoursAndLayers(reader);
        read_status = reader.ReadFile(file.c_str());
        if (read_status == IFSelect_RetDone) {
            TColStd_SequenceOfAsciiString lengths, angles, solid_angles;
            reader.ChangeReader().FileUnits(lengths, angles, solid_angles);
            if (!lengths.IsEmpty()) out.file_unit = lengths.First().ToCString();
            transferred = reader.Transfer(out.doc);
        }
    } else {
        IGESCAFControl_Reader reader;
        KeepNamesColoursAndLayers(reader);
        read_status = reader.ReadFile(file.c_str());
        if (read_status == IFSelect_RetDone) {
            const Handle(IGESData_IGESModel) model = reader.IGESModel();
            if (!model.IsNull() && !model->GlobalSection().UnitName().IsNull()) {
                out.file_unit = model->GlobalSection().UnitName()->ToCString();
            }
            transferred = reader.Transfer(out.doc);
        }
    }
    if (read_status != IFSelect_RetDone) {
        const std::string said = recorder.FirstProblem();
        return DataLossError(
            "{}: Open CASCADE cannot read it as {} ({}{}): the file is damaged or not {}",
            file.string(), out.format,
            read_status == IFSelect_RetVoid ? "nothing to read" : "syntax or structure errors",
            said.empty() ? "" : "; it said: " + said, out.format);
    }
    if (!transferred) {
        return DataLossError(
            "{}: Open CASCADE read the {} file but could not turn its entities into shapes",
            file.string(), out.format);
    }
    return out;
}

class Plugin final : public CadPlugin {
  public:
    StatusOr<CadReadSummary> ReadBrep(
        const std::filesystem::path& file, const CadReadOptions& options,
        const std::function<Status(IndexedMesh&&)>& emit,
        std::vector<store::MaterialRecord>& materials) const override {
        try {
            return Read(file, options, emit, materials);
        } catch (const Standard_Failure& e) {
            return DataLossError("{}: Open CASCADE failed on it: {} ({})", file.string(),
                                 e.GetMessageString(), e.DynamicType()->Name());
        } catch (const std::bad_alloc&) {
            return ResourceExhaustedError("{}: out of memory reading it with Open CASCADE",
                                          file.string());
        }
    }

  private:
    static StatusOr<CadReadSummary> Read(const std::filesystem::path& file,
                                         const CadReadOptions& options,
                                         const std::function<Status(IndexedMesh&&)>& emit,
                                         std::vector<store::MaterialRecord>& materials) {
        // Open CASCADE reports on standard output ("Statistics on Transfer"...): nave's output
        // is its own, and what the library says goes into the error message.
        const Handle(Message_Messenger)& messenger = Message::DefaultMessenger();
        messenger->RemovePrinters(STANDARD_TYPE(Message_PrinterOStream));
        messenger->RemovePrinters(STANDARD_TYPE(MessageRecorder));
        Handle(MessageRecorder) recorder = new MessageRecorder();
        messenger->AddPrinter(recorder);
        NAVE_ASSIGN_OR_RETURN(ReadDocument read, ReadIntoDocument(file, *recorder));
        CadReadSummary summary;
        summary.format = read.format;
        summary.file_unit = read.file_unit;
        const Handle(XCAFDoc_ShapeTool) shapes = XCAFDoc_DocumentTool::ShapeTool(read.doc->Main());
        const Handle(XCAFDoc_LayerTool) layers = XCAFDoc_DocumentTool::LayerTool(read.doc->Main());

        // The model's box (from the surfaces, before any mesh) gives the default grid step, and
        // the placements of every part tell when its triangulation can be dropped.
        Bnd_Box box;
        TDF_LabelSequence roots;
        shapes->GetFreeShapes(roots);
        for (const TDF_Label& root : roots) BRepBndLib::Add(shapes->GetShape(root), box, false);
        std::unordered_map<std::string, uint64_t> placements_left;
        for (XCAFPrs_DocumentExplorer it(read.doc, XCAFPrs_DocumentExplorerFlags_OnlyLeafNodes);
             it.More(); it.Next()) {
            ++placements_left[EntryOf(it.Current().RefLabel)];
        }
        if (box.IsVoid() || placements_left.empty()) {
            return DataLossError("{}: the {} file holds no shape", file.string(), read.format);
        }
        const double diagonal = std::sqrt(box.SquareExtent());
        const double step = options.precision > 0 ? options.precision : diagonal / double(1 << 20);
        summary.linear_deflection = kDeflectionGridSteps * step;
        summary.angular_deflection = kAngularDeflection;
        summary.parts = placements_left.size();

        MaterialTable table(materials);
        for (XCAFPrs_DocumentExplorer it(read.doc, XCAFPrs_DocumentExplorerFlags_OnlyLeafNodes);
             it.More(); it.Next()) {
            const XCAFPrs_DocumentNode& node = it.Current();
            const TopoDS_Shape part = XCAFDoc_ShapeTool::GetShape(node.RefLabel);
            // Meshes (in its constructor) only faces without a fine enough triangulation: a part
            // placed again is already meshed.
            const BRepMesh_IncrementalMesh mesher(part, summary.linear_deflection, false,
                                                  summary.angular_deflection, false);
            std::string name = LayerOf(layers, node.Label);
            if (name.empty()) name = LayerOf(layers, node.RefLabel);
            if (name.empty()) name = NameOf(node.RefLabel);
            if (name.empty()) name = NameOf(node.Label);
            if (name.empty()) name = "part";
            const std::string where = fmt::format("{} part '{}' ({})", file.filename().string(),
                                                  name, node.Id.ToCString());
            NAVE_RETURN_IF_ERROR(EmitPart(node, name, where, table, emit, summary));
            ++summary.instances;
            if (--placements_left[EntryOf(node.RefLabel)] == 0) {
                for (TopExp_Explorer face(part, TopAbs_FACE); face.More(); face.Next()) {
                    TopLoc_Location loc;
                    if (BRep_Tool::Triangulation(TopoDS::Face(face.Current()), loc).IsNull()) {
                        ++summary.faces_without_mesh;
                    }
                }
                // The part's last placement: its triangles are in nave's hands now.
                BRepTools::Clean(part);
            }
        }
        XCAFApp_Application::GetApplication()->Close(read.doc);
        return summary;
    }

    // One placed part: its faces' triangles grouped by material, one mesh each.
    static Status EmitPart(const XCAFPrs_DocumentNode& node, const std::string& name,
                           const std::string& where, MaterialTable& table,
                           const std::function<Status(IndexedMesh&&)>& emit,
                           CadReadSummary& summary) {
        std::map<uint32_t, IndexedMesh> by_material;
        for (RWMesh_FaceIterator face(node.RefLabel, node.Location, true, node.Style); face.More();
             face.Next()) {
            if (face.IsEmptyMesh()) continue;
            std::optional<std::array<float, 4>> rgba;
            if (face.HasFaceColor()) {
                // Quantity_Color holds linear RGB (Open CASCADE 7.5 and later), as
                // MaterialRecord does.
                const Quantity_Color& rgb = face.FaceColor().GetRGB();
                rgba = {float(rgb.Red()), float(rgb.Green()), float(rgb.Blue()),
                        face.FaceColor().Alpha()};
            }
            const uint32_t material = table.Find(name, rgba);
            IndexedMesh& mesh = by_material[material];
            mesh.material = material;
            const uint32_t base = uint32_t(mesh.positions.size());
            const bool normals = face.HasNormals();
            for (int i = face.NodeLower(); i <= face.NodeUpper(); ++i) {
                const gp_Pnt p = face.NodeTransformed(i);
                mesh.positions.push_back(Vec3f(float(p.X()), float(p.Y()), float(p.Z())));
                if (normals) {
                    const gp_Dir n = face.NormalTransformed(i);
                    mesh.normals.push_back(Vec3f(float(n.X()), float(n.Y()), float(n.Z())));
                }
            }
            for (int t = face.ElemLower(); t <= face.ElemUpper(); ++t) {
                int a = 0, b = 0, c = 0;
                // Counter-clockwise seen from outside, whatever the face's orientation.
                face.TriangleOriented(t).Get(a, b, c);
                const int lower = face.NodeLower();
                mesh.indices.push_back(base + uint32_t(a - lower));
                mesh.indices.push_back(base + uint32_t(b - lower));
                mesh.indices.push_back(base + uint32_t(c - lower));
            }
        }
        for (auto& [material, mesh] : by_material) {
            // A mesh takes normals for all its positions or none: a face without them (no
            // surface to take them from) leaves its whole mesh to flat shading.
            if (mesh.normals.size() != mesh.positions.size()) mesh.normals.clear();
            summary.triangles += mesh.indices.size() / 3;
            mesh.where = where;
            NAVE_RETURN_IF_ERROR(emit(std::move(mesh)));
        }
        return Status::Ok();
    }
};

}  // namespace
}  // namespace nave::preprocess::cad

extern "C" __attribute__((visibility("default"))) nave::preprocess::CadPlugin* NaveCreateCadPlugin(
    int version) {
    if (version != nave::preprocess::kCadPluginVersion) return nullptr;
    return new nave::preprocess::cad::Plugin();
}
