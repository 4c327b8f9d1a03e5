#include "cad_fixtures.h"

#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <IGESCAFControl_Writer.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_PrinterOStream.hxx>
#include <Quantity_Color.hxx>
#include <STEPCAFControl_Writer.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_ColorTool.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <gp_Trsf.hxx>

namespace nave::preprocess::testing {
namespace {

double MetresPer(const std::string& unit) {
    if (unit == "MM") return 0.001;
    if (unit == "INCH") return 0.0254;
    return 1.0;
}

// The chapel in a new document whose lengths are in `unit`.
Handle(TDocStd_Document) Chapel(const std::string& unit) {
    Message::DefaultMessenger()->RemovePrinters(STANDARD_TYPE(Message_PrinterOStream));
    Handle(TDocStd_Document) doc;
    XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", doc);
    const double m = 1.0 / MetresPer(unit);
    XCAFDoc_DocumentTool::SetLengthUnit(doc, MetresPer(unit));
    Handle(XCAFDoc_ShapeTool) shapes = XCAFDoc_DocumentTool::ShapeTool(doc->Main());
    Handle(XCAFDoc_ColorTool) colours = XCAFDoc_DocumentTool::ColorTool(doc->Main());
    const TDF_Label chapel = shapes->NewShape();
    TDataStd_Name::Set(chapel, "Chapel");
    const TDF_Label altar =
        shapes->AddShape(BRepPrimAPI_MakeBox(1 * m, 2 * m, 0.5 * m).Shape(), false);
    TDataStd_Name::Set(altar, "Altar");
    colours->SetColor(altar, Quantity_Color(0.8, 0.1, 0.1, Quantity_TOC_RGB), XCAFDoc_ColorSurf);
    const TDF_Label column =
        shapes->AddShape(BRepPrimAPI_MakeCylinder(kColumnRadius * m, 1 * m).Shape(), false);
    TDataStd_Name::Set(column, "Column");
    gp_Trsf east, north;
    east.SetTranslation(gp_Vec(5 * m, 0, 0));
    north.SetTranslation(gp_Vec(0, 5 * m, 0));
    shapes->AddComponent(chapel, altar, TopLoc_Location());
    shapes->AddComponent(chapel, column, TopLoc_Location(east));
    shapes->AddComponent(chapel, column, TopLoc_Location(north));
    shapes->UpdateAssemblies();
    return doc;
}

}  // namespace

bool WriteChapelStep(const std::filesystem::path& path, const std::string& unit) {
    Handle(TDocStd_Document) doc = Chapel(unit);
    Interface_Static::SetCVal("write.step.unit", unit.c_str());
    STEPCAFControl_Writer writer;
    writer.SetColorMode(true);
    writer.SetNameMode(true);
    const bool ok =
        writer.Transfer(doc, STEPControl_AsIs) && writer.Write(path.c_str()) == IFSelect_RetDone;
    XCAFApp_Application::GetApplication()->Close(doc);
    return ok;
}

bool WriteChapelIges(const std::filesystem::path& path) {
    Handle(TDocStd_Document) doc = Chapel("MM");
    IGESCAFControl_Writer writer;
    writer.SetColorMode(true);
    writer.SetNameMode(true);
    const bool ok = writer.Transfer(doc) && writer.Write(path.c_str());
    XCAFApp_Application::GetApplication()->Close(doc);
    return ok;
}

}  // namespace nave::preprocess::testing
