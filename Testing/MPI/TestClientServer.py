"""SDFCage in a client-server session: a pvpython client connected to a pvserver on 2 ranks.

Run (by RunClientServer.py): pvpython TestClientServer.py HOST PORT <SDFCage.so> <scratch dir>
with PYTHONPATH holding the `sdfcage` package (for the serial reference, computed here in the
client with plain VTK).
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from paraview.simple import *  # noqa: F401,F403
from paraview import servermanager

import sdfcage
from mpi_compare import Checker, same_surface, same_results
from mpi_pieces import write_pieces_vtp, torus_mesh
from vtkmodules.vtkFiltersSources import vtkSphereSource

host, port, plugin, scratch = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4]
chk = Checker()

Connect(host, port)
chk.check(servermanager.ActiveConnection.IsRemote(), "connected to the server on port %d" % port)
ranks = servermanager.ActiveConnection.GetNumberOfDataPartitions()
chk.check(ranks == 2, "the server runs on %d ranks" % ranks)
LoadPlugin(plugin, remote=True, ns=globals())
chk.check("SDFCage" in globals(), "the plugin's proxies are defined after loading it on the server")

RESULTS = ["Status", "EnclosureVerified", "VerticesReached", "MergedPoints", "InputClosed", "InputGenus", "SignMode",
           "EnvelopeGenus", "MeasuredClearance"]


def serial(mesh, iso, n):
    f = sdfcage.vtkSDFCageFilter()
    f.SetInputData(mesh)
    f.SetIsoValue(iso)
    f.SetTargetNumberOfVertices(n)
    f.Update()
    return f.GetOutput(0)


# a distributed source on the server
sphere = Sphere(ThetaResolution=32, PhiResolution=32)
cage = SDFCage(Input=sphere, IsoValue=0.04, TargetNumberOfVertices=100)
cage.UpdatePipeline()
out = servermanager.Fetch(cage)
s = vtkSphereSource()
s.SetThetaResolution(32)
s.SetPhiResolution(32)
s.Update()
ref = serial(s.GetOutput(), 0.04, 100)
same_surface(chk, "sphere cage (client-server)", out, ref)
same_results(chk, "sphere cage (client-server)", out, ref, RESULTS)
chk.check(cage.GetDataInformation().GetNumberOfPoints() == ref.GetNumberOfPoints(),
          "the cage is on one server rank only (%d points over the ranks)" % cage.GetDataInformation().GetNumberOfPoints())
cage.UpdatePropertyInformation()
chk.check(cage.GetProperty("StatusInfo").GetElement(0) == "Ok", "information property StatusInfo Ok on the client")

# a file the server's reader splits into pieces (the client and the server share this disk)
torus = torus_mesh()
path = os.path.join(scratch, "cs_torus_4pieces.vtp")
write_pieces_vtp(torus, path, 4)
reader = XMLPolyDataReader(FileName=[path])
tcage = SDFCage(Input=reader, IsoValue=0.02, TargetNumberOfVertices=150)
tcage.UpdatePipeline()
tout = servermanager.Fetch(tcage)
tref = serial(torus, 0.02, 150)
same_surface(chk, "torus cage from 4 pieces (client-server)", tout, tref)
same_results(chk, "torus cage from 4 pieces (client-server)", tout, tref, [r for r in RESULTS if r != "MergedPoints"])

# the quality judge on the server
quality = CageQuality(Input=cage, Source=sphere)
quality.UpdatePipeline()
q = servermanager.Fetch(quality)
chk.check(q.GetFieldData().GetArray("Encloses").GetValue(0) == 1, "Cage Quality on the server: Encloses 1")

Disconnect()
chk.finish()
