"""SDFCage: the plugin XML must agree with the C++ classes (defaults, ranges, commands).

Run: PYTHONPATH=<build>/lib/python3/dist-packages /usr/bin/python3 TestXMLDefaults.py SDFCage.xml
"""
import sys
import xml.etree.ElementTree as ET

import vtk  # noqa: F401  (ParaView's VTK, needed before sdfcage)
import sdfcage

failures = []


def check(condition, message):
    print(("ok:   " if condition else "FAIL: ") + message)
    if not condition:
        failures.append(message)


def parse_numbers(text):
    return [float(v) for v in text.split()]


def main(xml_path):
    root = ET.parse(xml_path).getroot()
    proxies = [p for group in root.findall("ProxyGroup") for p in group
               if p.get("class", "").startswith("vtk")]
    check(len(proxies) >= 3, "the XML declares the filter, the reader and the writer")
    for proxy in proxies:
        cls = proxy.get("class")
        check(hasattr(sdfcage, cls), "%s: class %s is wrapped in sdfcage" % (proxy.get("name"), cls))
        if not hasattr(sdfcage, cls):
            continue
        instance = getattr(sdfcage, cls)()
        for prop in proxy:
            if prop.tag not in ("DoubleVectorProperty", "IntVectorProperty",
                                "StringVectorProperty", "InputProperty"):
                continue
            name = prop.get("name")
            command = prop.get("command")
            check(command is not None and hasattr(instance, command),
                  "%s.%s: command %s exists" % (cls, name, command))
            if prop.get("information_only") == "1" or prop.tag in ("InputProperty",
                                                                    "StringVectorProperty"):
                continue
            if not command.startswith("Set"):
                continue
            getter = "Get" + command[3:]
            check(hasattr(instance, getter), "%s: %s exists" % (cls, getter))
            default = prop.get("default_values")
            if default is not None and hasattr(instance, getter):
                cxx = getattr(instance, getter)()
                xml_value = parse_numbers(default)
                cxx_value = list(cxx) if isinstance(cxx, (tuple, list)) else [float(cxx)]
                check(all(abs(a - b) <= 1e-12 * max(1.0, abs(b))
                          for a, b in zip(xml_value, cxx_value)) and len(xml_value) == len(cxx_value),
                      "%s.%s: XML default %s == C++ default %s" % (cls, name, xml_value, cxx_value))
            # Range domains: the XML minimum must equal the C++ clamp minimum (the maximum of
            # the GUI slider may be tighter than the C++ clamp, never wider).
            for domain in prop:
                if domain.tag not in ("DoubleRangeDomain", "IntRangeDomain"):
                    continue
                lo_getter = getter + "MinValue"
                hi_getter = getter + "MaxValue"
                if hasattr(instance, lo_getter) and domain.get("min") is not None:
                    check(float(domain.get("min")) == getattr(instance, lo_getter)(),
                          "%s.%s: XML min %s == C++ clamp min %s" % (
                              cls, name, domain.get("min"), getattr(instance, lo_getter)()))
                if hasattr(instance, hi_getter) and domain.get("max") is not None:
                    check(float(domain.get("max")) <= getattr(instance, hi_getter)(),
                          "%s.%s: XML max %s <= C++ clamp max %s" % (
                              cls, name, domain.get("max"), getattr(instance, hi_getter)()))
            # Boolean properties must be backed by a boolean-ish C++ value.
            if prop.find("BooleanDomain") is not None and hasattr(instance, getter):
                check(getattr(instance, getter)() in (0, 1, True, False),
                      "%s.%s: boolean default" % (cls, name))

    # Every settable C++ parameter of the filter has a property (nothing forgotten).
    filter_proxy = [p for p in proxies if p.get("class") == "vtkSDFCageFilter"][0]
    commands = {p.get("command") for p in filter_proxy}
    for parameter in ("TargetNumberOfVertices", "IsoValue", "VoxelSize", "MinimumClearance", "Adaptivity", "MaximumRefinements",
                      "GenerateDistanceField", "NumberOfThreads"):
        check("Set" + parameter in commands, "vtkSDFCageFilter.%s has an XML property" % parameter)
    for parameter in ("Optimize", "Energy", "TargetSpacing", "BarrierWeight", "BarrierDistance",
                      "NumberOfIterations", "EdgeFlips"):
        check("Set" + parameter in commands, "vtkSDFCageFilter.%s has an XML property" % parameter)
    optimize_proxy = [p for p in proxies if p.get("class") == "vtkCageOptimizeFilter"]
    check(len(optimize_proxy) == 1, "the XML declares vtkCageOptimizeFilter")
    if optimize_proxy:
        o = optimize_proxy[0]
        ocommands = {p.get("command") for p in o}
        for parameter in ("Energy", "TargetSpacing", "BarrierWeight", "BarrierDistance",
                          "NumberOfIterations", "EdgeFlips", "MinimumClearance"):
            check("Set" + parameter in ocommands, "vtkCageOptimizeFilter.%s has an XML property" % parameter)
        inputs = {p.get("name"): p.get("command") for p in o.findall("InputProperty")}
        check(inputs.get("Input") == "SetInputConnection", "the cage is Input: %s" % (inputs.get("Input"),))
        check(inputs.get("Source") == "SetSourceConnection", "the mesh is Source: %s" % (inputs.get("Source"),))
        menu = o.find("Hints/ShowInMenu")
        check(menu is not None and menu.get("category") == "Cage Generation", "Cage Optimize in the menu")
    ports = [p.get("name") for p in filter_proxy.findall("OutputPort")]
    check(ports == ["Cage", "Envelope", "Distance Field", "Nested Cages"], "named output ports %s" % ports)
    nested = [p for p in filter_proxy if p.get("name") == "NestedVertexCounts"]
    check(len(nested) == 1 and nested[0].get("set_number_command") == "SetNumberOfNestedLevels"
          and nested[0].get("repeat_command") == "1" and nested[0].get("number_of_elements") == "0",
          "Nested Levels: a repeatable list, empty by default (one cage)")
    menu = filter_proxy.find("Hints/ShowInMenu")
    check(menu is not None and menu.get("category") == "Cage Generation",
          "shown in the Cage Generation menu")

    if failures:
        print("%d failure(s)" % len(failures))
        return 1
    print("XML and C++ agree")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
