// Internal hinges: see internal_joints.h.
#include "sim/internal_joints.h"

#include <regex>

#include "core/error.h"
#include "sim/mjcf_text.h"

namespace exotwin {
namespace {

const char* kJoint[2] = {"hip", "knee"};
const char* kBody[2] = {"exo_thigh", "exo_shank"};

// The <joint .../> tag named `name` inside [from, to) of xml; throws if absent.
std::smatch FindJointTag(const std::string& xml, size_t from, size_t to, const std::string& name,
                         const std::string& source) {
  const std::regex tag(R"(<joint\b[^>]*\sname\s*=\s*(["']))" + name + R"(\1[^>]*/>)");
  std::smatch m;
  const auto first = xml.begin() + static_cast<long>(from), last = xml.begin() + static_cast<long>(to);
  if (!std::regex_search(first, last, m, tag))
    throw InputError(source + ": no self-closing <joint name=\"" + name + "\" .../> in its body");
  return m;
}

std::string AxisOf(const std::string& joint_tag) {
  static const std::regex axis(R"(\saxis\s*=\s*(["'])([^"']*)\1)");
  std::smatch m;
  return std::regex_search(joint_tag, m, axis) ? m[2].str() : "0 0 1";  // MJCF's default hinge axis
}

}  // namespace

InternalJoints InternalJointsOf(const PlantEffects& fx) {
  InternalJoints s;
  for (int j = 0; j < 2; ++j) {
    if (fx.backlash[j] != 0) {
      s.kind[j] = InternalHinge::kRotor;
      s.backlash[j] = true;
    } else if (fx.compliance[j] != 0) {
      s.kind[j] = fx.compliant_human ? InternalHinge::kHuman : InternalHinge::kRotor;
    }
  }
  return s;
}

std::string InternalHingeName(int j, const InternalJoints& s) {
  return std::string(kJoint[j]) + (s.backlash[j] ? "_backlash" : "_compliance");
}

std::string RotorBodyName(int j) { return std::string(kJoint[j]) + "_rotor"; }

std::string AddInternalJoints(const std::string& xml_in, const std::string& source, const InternalJoints& s) {
  std::string xml = xml_in;
  for (int j = 1; j >= 0; --j) {
    if (s.kind[j] == InternalHinge::kNone) continue;
    if (s.kind[j] == InternalHinge::kHuman) {
      const BodyElement b = FindBodyElement(xml, "human_shank", source);
      const BodyElement knee_body = FindBodyElement(xml, kBody[j], source);
      const std::smatch jt = FindJointTag(xml, knee_body.open_end, knee_body.end, kJoint[j], source);
      xml.insert(b.open_end, "<joint name=\"" + InternalHingeName(j, s) + "\" type=\"hinge\" axis=\"" +
                                 AxisOf(jt[0].str()) + "\"/>");
      continue;
    }
    const BodyElement b = FindBodyElement(xml, kBody[j], source);
    const std::smatch jt = FindJointTag(xml, b.open_end, b.end, kJoint[j], source);
    const std::string joint_tag = jt[0].str();
    const size_t jt_begin = static_cast<size_t>(jt.position(0)) + b.open_end;
    const size_t jt_end = jt_begin + joint_tag.size();
    // The body's attributes other than its name (its placement) move to the rotor.
    static const std::regex name_attr(R"(\sname\s*=\s*(["'])[^"']*\1)");
    std::string attrs = std::regex_replace(xml.substr(b.begin + 5, b.open_end - 1 - (b.begin + 5)), name_attr, "");
    const std::string rotor_open = "<body name=\"" + RotorBodyName(j) + "\"" + attrs + ">" + joint_tag +
                                   "<inertial pos=\"0 0 0\" mass=\"1\" diaginertia=\"1 1 1\"/>";
    const std::string body_open = std::string("<body name=\"") + kBody[j] + "\">" + "<joint name=\"" +
                                  InternalHingeName(j, s) + "\" type=\"hinge\" axis=\"" + AxisOf(joint_tag) + "\"" +
                                  (s.backlash[j] ? " limited=\"true\" range=\"-0.01 0.01\"" : " limited=\"false\"") +
                                  "/>";
    xml = xml.substr(0, b.begin) + rotor_open + body_open + xml.substr(b.open_end, jt_begin - b.open_end) +
          xml.substr(jt_end, b.end - jt_end) + "</body>" + xml.substr(b.end);
  }
  return xml;
}

}  // namespace exotwin
