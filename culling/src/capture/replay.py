# lightcull's RenderDoc replay helper (docs/RENDERDOC.md). The lightcull
# binary runs this with the system python3 in a process of its own (a process
# that captures must not replay; a replay that crashes or hangs takes only
# this process with it) and reads one JSON object from its stdout.
#
#   info CAPTURE [EVENT]                 the capture's actions; with EVENT, the
#                                        compute bindings at that event
#   read CAPTURE EVENT DIR KEY=SPEC...   the bound range of each named binding
#                                        after EVENT, written to DIR/KEY.bin
#
# SPEC names a binding of the event's compute pipeline: "SET.BINDING", or a
# debug name (the resource's, or the shader's variable name). Errors: a JSON
# object {"error": "..."} and exit status 1; exit 3 when the renderdoc
# module is missing.
import json
import os
import sys


def reply(obj, status=0):
    sys.stdout.write(json.dumps(obj))
    sys.stdout.flush()
    os._exit(status)  # RenderDoc's threads must not keep the process alive


try:
    import renderdoc as rd
except ImportError:
    reply({"error": "the RenderDoc Python module is not installed for " + sys.executable +
           " (Debian 12: apt-get install python3-renderdoc)"}, 3)


def fail(message):
    reply({"error": message}, 1)


def result_text(result):
    """RenderDoc's result as its message ("File is corrupted: ..."), not the
    Python object's repr."""
    text = str(result)
    prefix = "<Result: '"
    if text.startswith(prefix) and text.endswith("'>"):
        text = text[len(prefix):-2]
    return text


def open_capture(path):
    rd.InitialiseReplay(rd.GlobalEnvironment(), [])
    cap = rd.OpenCaptureFile()
    result = cap.OpenFile(path, "", None)
    if result != rd.ResultCode.Succeeded:
        fail(path + ": not a RenderDoc capture RenderDoc " + rd.GetVersionString() + " can open: " + result_text(result))
    api = cap.DriverName()
    if api != "Vulkan":
        fail(path + ": a " + api + " capture; lightcull reads Vulkan captures only")
    if cap.LocalReplaySupport() != rd.ReplaySupport.Supported:
        fail(path + ": this machine cannot replay it (" + str(cap.LocalReplaySupport()) + ")")
    result, ctrl = cap.OpenCapture(rd.ReplayOptions(), None)
    if result != rd.ResultCode.Succeeded:
        fail(path + ": RenderDoc cannot replay it here: " + result_text(result))
    return cap, ctrl


def action_kind(a):
    f = a.flags
    if f & rd.ActionFlags.Dispatch:
        return "dispatch"
    if f & rd.ActionFlags.Drawcall:
        return "draw"
    if f & rd.ActionFlags.Copy:
        return "copy"
    if f & rd.ActionFlags.Clear:
        return "clear"
    if f & (rd.ActionFlags.PushMarker | rd.ActionFlags.SetMarker):
        return "marker"
    return "other"


def list_actions(ctrl):
    sf = ctrl.GetStructuredFile()
    out = []

    def walk(actions, markers):
        for a in actions:
            kind = action_kind(a)
            name = a.GetName(sf)
            if kind in ("dispatch", "draw", "copy", "clear"):
                out.append({"event": a.eventId, "name": name, "kind": kind, "markers": markers,
                            "dims": list(a.dispatchDimension) if kind == "dispatch" else []})
            inner = markers + [name] if (a.flags & rd.ActionFlags.PushMarker) else markers
            walk(a.children, inner)

    walk(ctrl.GetRootActions(), [])
    return out


def enum_name(enum, value):
    try:
        return enum(value).name
    except (ValueError, TypeError):
        return str(value)


def bindings_at(ctrl, event):
    ctrl.SetFrameEvent(event, True)
    names = {r.resourceId: r.name for r in ctrl.GetResources()}
    bufs = {b.resourceId: b for b in ctrl.GetBuffers()}
    texs = {t.resourceId: t for t in ctrl.GetTextures()}
    variables = {}
    state = ctrl.GetPipelineState()
    refl = state.GetShaderReflection(rd.ShaderStage.Compute)
    if refl is not None:
        mapping = state.GetBindpointMapping(rd.ShaderStage.Compute)
        for group, binds in ((refl.readWriteResources, mapping.readWriteResources),
                             (refl.readOnlyResources, mapping.readOnlyResources),
                             (refl.constantBlocks, mapping.constantBlocks)):
            for r in group:
                if 0 <= r.bindPoint < len(binds):
                    bp = binds[r.bindPoint]
                    variables.setdefault((bp.bindset, bp.bind), r.name)
    out = []
    vk = ctrl.GetVulkanPipelineState()
    for s, ds in enumerate(vk.compute.descriptorSets):
        for b, binding in enumerate(ds.bindings):
            for k, e in enumerate(binding.binds):
                rid = e.resourceResourceId
                if rid == rd.ResourceId.Null():
                    continue
                entry = {"set": s, "binding": b, "element": k, "resource": names.get(rid, str(rid)),
                         "variable": variables.get((s, b), ""), "descriptor": enum_name(rd.BindType, e.type)}
                if rid in bufs:
                    length = bufs[rid].length
                    offset = min(e.byteOffset, length)
                    size = length - offset if e.byteSize >= (1 << 63) else min(e.byteSize, length - offset)
                    entry.update({"kind": "buffer", "offset": offset, "size": size, "length": length})
                elif rid in texs:
                    t = texs[rid]
                    fmt = t.format
                    entry.update({"kind": "image", "width": t.width, "height": t.height,
                                  "format": fmt.Name(), "component_bytes": fmt.compByteWidth,
                                  "components": fmt.compCount, "component_type": enum_name(rd.CompType, fmt.compType),
                                  "samples": t.msSamp})
                else:
                    entry.update({"kind": "other"})
                out.append(entry)
    return out


def find_event(actions, event):
    for a in actions:
        if a["event"] == event:
            return a
    return None


# The description's JSON path of each binding key the caller reads.
FIELDS = {"lights": "lights.binding", "light_count": "lights.count.binding", "camera": "camera.binding",
          "depth": "depth.binding", "lists": "lists.binding", "counts": "lists.counts", "indices": "lists.indices",
          "offsets": "lists.offsets", "ranges": "lists.ranges", "masks": "lists.masks", "bins": "lists.bins",
          "order": "lists.order"}


def resolve(bindings, spec, event, key=None):
    parts = spec.split(".")
    if len(parts) == 2 and parts[0].isdigit() and parts[1].isdigit():
        hits = [b for b in bindings if b["set"] == int(parts[0]) and b["binding"] == int(parts[1])]
    else:
        hits = [b for b in bindings if spec in (b["resource"], b["variable"])]
        if not hits:
            hits = [b for b in bindings if b["resource"].endswith("." + spec)]
    hits = [b for b in hits if b["element"] == 0] or hits
    if not hits:
        known = ", ".join("%d.%d %s" % (b["set"], b["binding"], b["resource"]) for b in bindings)
        field = (FIELDS.get(key, key) + ": ") if key else ""
        fail("%sevent %d binds nothing named '%s' (its bindings: %s)" % (field, event, spec, known or "none"))
    if len(hits) > 1:
        field = (FIELDS.get(key, key) + ": ") if key else ""
        fail("%s'%s' names %d bindings at event %d: give SET.BINDING" % (field, spec, len(hits), event))
    return hits[0]


def dispatch_named(actions, what):
    """The event of the one dispatch `what` names (an event id, or text of
    its name or marker path), or None: the caller's findDispatch then says
    why, from the actions."""
    dispatches = [a for a in actions if a["kind"] == "dispatch"]
    if what.isdigit() and len(what) < 10:
        hits = [a for a in dispatches if a["event"] == int(what)]
    else:
        hits = [a for a in dispatches if what in a["name"] or what in " / ".join(a["markers"])]
    return hits[0]["event"] if len(hits) == 1 else None


def main(argv):
    if len(argv) < 2 or argv[0] not in ("info", "read"):
        fail("usage: info CAPTURE [EVENT] | read CAPTURE EVENT|dispatch:TEXT DIR KEY=SPEC...")
    cap, ctrl = open_capture(argv[1])
    actions = list_actions(ctrl)
    result = {"api": "Vulkan", "renderdoc": rd.GetVersionString(), "actions": actions}
    if len(argv) >= 3:
        if argv[2].startswith("dispatch:"):
            # The dispatch by name, resolved here: one replay reads it.
            event = dispatch_named(actions, argv[2][len("dispatch:"):])
            if event is None:
                ctrl.Shutdown()
                cap.Shutdown()
                reply(result)
                return
        else:
            event = int(argv[2])
        action = find_event(actions, event)
        if action is None:
            fail("%s has no dispatch, draw or copy at event %d" % (argv[1], event))
        result["event"] = event
        result["bindings"] = bindings_at(ctrl, event) if action["kind"] == "dispatch" else []
    if argv[0] == "read":
        out_dir = argv[3]
        read = {}
        for item in argv[4:]:
            key, spec = item.split("=", 1)
            b = resolve(result["bindings"], spec, event, key)
            rid = lookup_id(ctrl, b)
            if b["kind"] == "buffer":
                data = ctrl.GetBufferData(rid, b["offset"], b["size"])
            elif b["kind"] == "image":
                data = ctrl.GetTextureData(rid, rd.Subresource(0, 0, 0))
            else:
                fail("binding %d.%d (%s) is neither a buffer nor an image" % (b["set"], b["binding"], b["resource"]))
            with open(os.path.join(out_dir, key + ".bin"), "wb") as f:
                f.write(bytes(data))
            entry = dict(b)
            entry["bytes"] = len(data)
            read[key] = entry
        result["read"] = read
    ctrl.Shutdown()
    cap.Shutdown()
    reply(result)


def lookup_id(ctrl, b):
    vk = ctrl.GetVulkanPipelineState()
    return vk.compute.descriptorSets[b["set"]].bindings[b["binding"]].binds[b["element"]].resourceResourceId


try:
    main(sys.argv[1:])
except SystemExit:
    raise
except BaseException as e:  # one line, never a traceback
    fail("RenderDoc replay failed: %s: %s" % (type(e).__name__, e))
