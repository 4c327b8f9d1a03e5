// nave's IFC plugin (libnave_ifc.so): the implementation of preprocess/import/ifc_plugin.h with
// IFC++ (Debian's libifcplusplus, a 2019 snapshot of ifcplusplus). Its reader parses the STEP
// physical file into entities; its Carve geometry converter turns every product's representation
// into mesh sets in metres, with openings subtracted from the elements they void, and a placement
// matrix; styles become AppearanceData on the items. nave triangulates the mesh sets' polygons
// with Carve's own ear clipping, applies the placement and groups triangles by entity type and
// style.

#include <ifcpp/IFC4/include/IfcAnnotation.h>
#include <ifcpp/IFC4/include/IfcDoor.h>
#include <ifcpp/IFC4/include/IfcFeatureElementSubtraction.h>
#include <ifcpp/IFC4/include/IfcLabel.h>
#include <ifcpp/IFC4/include/IfcPlate.h>
#include <ifcpp/IFC4/include/IfcPresentationStyle.h>
#include <ifcpp/IFC4/include/IfcSpace.h>
#include <ifcpp/IFC4/include/IfcVirtualElement.h>
#include <ifcpp/IFC4/include/IfcWindow.h>
#include <ifcpp/geometry/Carve/GeometryConverter.h>
#include <ifcpp/model/BuildingModel.h>
#include <ifcpp/model/UnitConverter.h>
#include <ifcpp/reader/ReaderSTEP.h>

#include <algorithm>
#include <carve/triangulator.hpp>
#include <map>
#include <new>
#include <optional>

#include "preprocess/import/ifc_plugin.h"
#include "preprocess/import/material_table.h"
#include "src/core/file.h"

namespace nave::preprocess::ifc {
namespace {

std::string Narrow(const std::wstring& s) {
    std::string out;
    out.reserve(s.size());
    for (wchar_t c : s) out.push_back(c >= 0 && c < 128 ? char(c) : '?');
    return out;
}

// The schema the file's header names: FILE_SCHEMA(('IFC2X3')) -> "IFC2X3"; empty if none.
std::string SchemaOf(const std::string& content) {
    const size_t header_end = std::min(content.size(), content.find("ENDSEC"));
    const size_t at = content.rfind("FILE_SCHEMA", header_end);
    if (at == std::string::npos) return {};
    const size_t open = content.find('\'', at);
    const size_t close = open == std::string::npos ? open : content.find('\'', open + 1);
    if (close == std::string::npos || close > header_end || close - open > 64) return {};
    return content.substr(open + 1, close - open - 1);
}

// Keeps the first error IFC++ reports (it reports through a callback, with the entity it was
// reading), so that a refusal can name it.
struct ErrorRecorder {
    std::string first_error;
    static void Receive(void* self, shared_ptr<StatusCallback::Message> m) {
        auto* recorder = static_cast<ErrorRecorder*>(self);
        if (m->m_message_type != StatusCallback::MESSAGE_TYPE_ERROR ||
            !recorder->first_error.empty()) {
            return;
        }
        recorder->first_error = Narrow(m->m_message_text);
        if (m->m_entity != nullptr) {
            recorder->first_error += fmt::format(" (entity #{})", m->m_entity->m_entity_id);
        }
        if (recorder->first_error.size() > 300) {
            recorder->first_error = recorder->first_error.substr(0, 300) + "...";
        }
    }
};

// Spaces are rooms, openings holes and virtual elements boundaries: volumes for the model, not
// surfaces to render. Annotations are drawings.
bool Rendered(const shared_ptr<IfcObjectDefinition>& object) {
    return !dynamic_pointer_cast<IfcSpace>(object) &&
           !dynamic_pointer_cast<IfcFeatureElementSubtraction>(object) &&
           !dynamic_pointer_cast<IfcVirtualElement>(object) &&
           !dynamic_pointer_cast<IfcAnnotation>(object);
}

bool MayHaveGlazing(const shared_ptr<IfcObjectDefinition>& object) {
    return dynamic_pointer_cast<IfcWindow>(object) || dynamic_pointer_cast<IfcDoor>(object) ||
           dynamic_pointer_cast<IfcPlate>(object);
}

// The determinant of a placement's linear part (Carve's matrices are column-major: m[col][row]).
double Determinant3(const carve::math::Matrix& t) {
    const auto& m = t.m;
    return m[0][0] * (m[1][1] * m[2][2] - m[2][1] * m[1][2]) -
           m[1][0] * (m[0][1] * m[2][2] - m[2][1] * m[0][2]) +
           m[2][0] * (m[0][1] * m[1][2] - m[1][1] * m[0][2]);
}

class Plugin final : public IfcPlugin {
  public:
    StatusOr<CadReadSummary> ReadIfc(const std::filesystem::path& file,
                                     const std::function<Status(IndexedMesh&&)>& emit,
                                     std::vector<store::MaterialRecord>& materials) const override {
        try {
            return Read(file, emit, materials);
        } catch (const std::bad_alloc&) {
            return ResourceExhaustedError("{}: out of memory reading it with IFC++", file.string());
        } catch (const std::exception& e) {
            return DataLossError("{}: IFC++ failed on it: {}", file.string(), e.what());
        }
    }

  private:
    static StatusOr<CadReadSummary> Read(const std::filesystem::path& file,
                                         const std::function<Status(IndexedMesh&&)>& emit,
                                         std::vector<store::MaterialRecord>& materials) {
        // Read by nave and handed over as text: IFC++'s own file reader converts the path through
        // a locale that a minimal system lacks, and then reads nothing without a word.
        NAVE_ASSIGN_OR_RETURN(std::string content, ReadFileToString(file));
        auto model = std::make_shared<BuildingModel>();
        auto converter = std::make_shared<GeometryConverter>(model);
        auto reader = std::make_shared<ReaderSTEP>();
        ErrorRecorder errors;
        reader->setMessageCallBack(&errors, &ErrorRecorder::Receive);
        converter->setMessageCallBack(&errors, &ErrorRecorder::Receive);
        const std::string schema = SchemaOf(content);
        reader->loadModelFromString(content, model);
        content.clear();
        content.shrink_to_fit();
        if (model->getMapIfcEntities().empty()) {
            return DataLossError(
                "{}: IFC++ found no IFC entity in it: the file is damaged or not "
                "IFC{}",
                file.string(),
                errors.first_error.empty() ? "" : " (it said: " + errors.first_error + ")");
        }
        CadReadSummary summary;
        // IFC++ reads IFC 2x3 into its IFC4 classes and reports IFC4 either way: the header says
        // which the file is.
        summary.format = schema.empty() ? "IFC" : schema;
        const double metres = model->getUnitConverter()->getLengthInMeterFactor();
        summary.file_unit = fmt::format("{:g} m", metres);
        converter->convertGeometry();

        MaterialTable table(materials);
        std::map<std::string, uint64_t> by_kind;
        for (auto& [id, shape] : converter->getShapeInputData()) {
            const shared_ptr<IfcObjectDefinition> object = shape->m_ifc_object_definition.lock();
            if (!object) continue;
            const std::string kind = object->className();
            if (!Rendered(object)) {
                ++summary.skipped_products;
                continue;
            }
            const carve::math::Matrix placement = shape->getTransform();
            const bool mirrored = Determinant3(placement) < 0;
            std::map<uint32_t, IndexedMesh> by_material;
            for (const auto& representation : shape->m_vec_representations) {
                for (const auto& item : representation->m_vec_item_data) {
                    const uint32_t material =
                        MaterialOf(*model, object, kind, *item, shape->getAppearances(), table);
                    IndexedMesh& mesh = by_material[material];
                    mesh.material = material;
                    for (const auto& set : item->m_meshsets)
                        AddMeshSet(*set, placement, mirrored, mesh);
                    for (const auto& set : item->m_meshsets_open)
                        AddMeshSet(*set, placement, mirrored, mesh);
                }
            }
            bool any = false;
            for (auto& [material, mesh] : by_material) {
                if (mesh.indices.empty()) continue;
                any = true;
                const uint64_t triangles = mesh.indices.size() / 3;
                summary.triangles += triangles;
                by_kind[kind] += triangles;
                mesh.where = fmt::format("{} entity #{} ({})", file.filename().string(), id, kind);
                NAVE_RETURN_IF_ERROR(emit(std::move(mesh)));
            }
            if (any) ++summary.instances;
        }
        summary.parts = summary.instances;
        summary.by_kind.assign(by_kind.begin(), by_kind.end());
        if (summary.triangles == 0) {
            return DataLossError(
                "{}: the {} file holds no geometry IFC++ could turn into surfaces{}", file.string(),
                summary.format,
                errors.first_error.empty() ? "" : " (it said: " + errors.first_error + ")");
        }
        return summary;
    }

    // "IfcWall:Limestone" (the item's surface style by name), "IfcWall" (unnamed or no style);
    // transparent items of windows, doors and plates are their glazing.
    static uint32_t MaterialOf(BuildingModel& model, const shared_ptr<IfcObjectDefinition>& object,
                               const std::string& kind, const ItemShapeData& item,
                               const std::vector<shared_ptr<AppearanceData>>& product,
                               MaterialTable& table) {
        shared_ptr<AppearanceData> style;
        for (const auto& a : item.m_vec_item_appearances) {
            if (a && a->m_apply_to_geometry_type != AppearanceData::GEOM_TYPE_CURVE) style = a;
        }
        if (!style) {
            for (const auto& a : product) {
                if (a && a->m_apply_to_geometry_type != AppearanceData::GEOM_TYPE_CURVE) style = a;
            }
        }
        std::string name = kind;
        std::optional<std::array<float, 4>> rgba;
        if (style) {
            // IFC++ keeps a style's colour in linear [0, 1] and its opacity as "transparency".
            rgba = {float(style->m_color_diffuse.r()), float(style->m_color_diffuse.g()),
                    float(style->m_color_diffuse.b()), float(style->m_transparency)};
            const bool transparent = style->m_transparency < 0.99 || style->m_set_transparent;
            if (transparent && MayHaveGlazing(object)) name += std::string(" ") + kIfcGlazingWord;
            const auto& entities = model.getMapIfcEntities();
            auto it = entities.find(style->m_step_style_id);
            if (it != entities.end()) {
                auto presentation = dynamic_pointer_cast<IfcPresentationStyle>(it->second);
                if (presentation && presentation->m_Name &&
                    !presentation->m_Name->m_value.empty()) {
                    name += ":" + Narrow(presentation->m_Name->m_value);
                }
            }
        }
        return table.Find(name, rgba);
    }

    // The polygons of a Carve mesh set, triangulated by ear clipping in their own plane, placed.
    static void AddMeshSet(const carve::mesh::MeshSet<3>& set, const carve::math::Matrix& placement,
                           bool mirrored, IndexedMesh& out) {
        std::vector<carve::mesh::MeshSet<3>::vertex_t*> corners;
        std::vector<carve::geom2d::P2> projected;
        std::vector<carve::triangulate::tri_idx> triangles;
        for (const carve::mesh::Mesh<3>* mesh : set.meshes) {
            for (const carve::mesh::Face<3>* face : mesh->faces) {
                face->getVertices(corners);
                if (corners.size() < 3) continue;
                const uint32_t base = uint32_t(out.positions.size());
                for (const auto* v : corners) {
                    const carve::geom::vector<3> p = placement * v->v;
                    out.positions.push_back(Vec3f(float(p.x), float(p.y), float(p.z)));
                }
                triangles.clear();
                if (corners.size() == 3) {
                    triangles.emplace_back(0, 1, 2);
                } else {
                    projected.clear();
                    for (const auto* v : corners) projected.push_back(face->project(v->v));
                    carve::triangulate::triangulate(projected, triangles);
                }
                // Each triangle wound as its face: counter-clockwise around the face's normal, and
                // once more reversed by a mirroring placement.
                const carve::geom::vector<3> normal = face->plane.N;
                for (const auto& t : triangles) {
                    const auto& a = corners[t.a]->v;
                    const auto& b = corners[t.b]->v;
                    const auto& c = corners[t.c]->v;
                    const bool flipped = (carve::geom::dot(carve::geom::cross(b - a, c - a),
                                                           normal) < 0) != mirrored;
                    out.indices.push_back(base + t.a);
                    out.indices.push_back(base + (flipped ? t.c : t.b));
                    out.indices.push_back(base + (flipped ? t.b : t.c));
                }
            }
        }
    }
};

}  // namespace
}  // namespace nave::preprocess::ifc

extern "C" __attribute__((visibility("default"))) nave::preprocess::IfcPlugin* NaveCreateIfcPlugin(
    int version) {
    if (version != nave::preprocess::kIfcPluginVersion) return nullptr;
    return new nave::preprocess::ifc::Plugin();
}
