"""The benchmark problems in Exudyn.

Pendulum: ObjectBeamGeometricallyExact (the 3-D Reissner–Simo beam,
interpolated on SE(3), constant strain per element, consistent mass matrix
of linear interpolation) between NodeRigidBodyEP nodes (Euler parameters); gravity
as LoadMassProportional on every element; the pin is a GenericJoint to the
ground at x = 0 leaving only the rotation about global y free.

Heavy top: ObjectRigidBody (node at the centre of mass, Euler parameters)
created by MainSystem.CreateRigidBody, held by an ObjectJointSpherical at the
origin (MainSystem.CreateSphericalJoint).

Both are integrated by Exudyn's generalized-α (index-3 constraints) with a
fixed step; see `solver_settings` for every setting that differs from
Exudyn's defaults.
"""

import contextlib
import io
import time
from dataclasses import dataclass, field

import numpy as np
import exudyn as exu
from exudyn.itemInterface import (
    GenericJoint,
    LoadMassProportional,
    MarkerBodyMass,
    MarkerBodyRigid,
    MarkerNodeRigid,
    NodeRigidBodyEP,
    ObjectBeamGeometricallyExact,
    ObjectGround,
    SensorBody,
    SensorNode,
)
from exudyn.rigidBodyUtilities import RigidBodyInertia

from problems import GRAVITY, OUTPUT_PERIOD, RHO_INFINITY, HeavyTop, Pendulum, steps_for


@dataclass
class Run:
    """One time integration: the compared point at the output times, and what
    it cost."""

    ok: bool
    times: np.ndarray = field(default_factory=lambda: np.zeros(0))
    positions: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    wall_solve: float = 0.0  # s, SolveDynamic alone
    wall_total: float = 0.0  # s, model building + assembly + SolveDynamic
    steps: int = 0  # steps taken (more than nominal if Exudyn cut steps)
    newton_iterations: int = 0
    jacobians: int = 0
    message: str = ""


def beam_section(p=Pendulum):
    s = exu.BeamSection()
    # order (axial, shear y, shear z, torsion, bending y, bending z)
    s.stiffnessMatrix = np.diag([p.EA, p.GA, p.GA, p.GJ, p.EI, p.EI])
    s.inertia = np.diag([p.rho_J, p.rho_I, p.rho_I])
    s.massPerLength = p.rho_A
    return s


def pendulum_model(n, p=Pendulum):
    """n elements from (0,0,0) to (L,0,0); returns (SC, mbs, tip sensor)."""
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    le = p.length / n
    section = beam_section(p)
    nodes = [
        mbs.AddNode(NodeRigidBodyEP(referenceCoordinates=[i * le, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]))
        for i in range(n + 1)
    ]
    for i in range(n):
        beam = mbs.AddObject(
            ObjectBeamGeometricallyExact(nodeNumbers=[nodes[i], nodes[i + 1]], length=le, sectionData=section)
        )
        mass = mbs.AddMarker(MarkerBodyMass(bodyNumber=beam))
        mbs.AddLoad(LoadMassProportional(markerNumber=mass, loadVector=[0.0, 0.0, -GRAVITY]))
    ground = mbs.AddObject(ObjectGround())
    m_ground = mbs.AddMarker(MarkerBodyRigid(bodyNumber=ground, localPosition=[0.0, 0.0, 0.0]))
    m_root = mbs.AddMarker(MarkerNodeRigid(nodeNumber=nodes[0]))
    # revolute about global y: all relative motion fixed except the rotation about y
    mbs.AddObject(GenericJoint(markerNumbers=[m_ground, m_root], constrainedAxes=[1, 1, 1, 1, 0, 1]))
    tip = mbs.AddSensor(
        SensorNode(nodeNumber=nodes[-1], storeInternal=True, outputVariableType=exu.OutputVariableType.Position)
    )
    mbs.Assemble()
    return SC, mbs, tip


def top_model(t=HeavyTop):
    """Returns (SC, mbs, centre-of-mass sensor)."""
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    ground = mbs.AddObject(ObjectGround())
    inertia = RigidBodyInertia(mass=t.mass, inertiaTensor=np.diag(t.inertia_com))
    body = mbs.CreateRigidBody(
        inertia=inertia,
        referencePosition=list(t.center_of_mass),
        initialVelocity=list(t.com_velocity0()),
        initialAngularVelocity=list(t.omega0),  # global; = material at t = 0
        gravity=[0.0, 0.0, -GRAVITY],
        nodeType=exu.NodeType.RotationEulerParameters,
    )
    mbs.CreateSphericalJoint(itemNumbers=[ground, body], position=[0.0, 0.0, 0.0])
    com = mbs.AddSensor(
        SensorBody(bodyNumber=body, storeInternal=True, outputVariableType=exu.OutputVariableType.Position)
    )
    mbs.Assemble()
    return SC, mbs, com


# Newton's relative tolerance. Exudyn's default, 1e-8, lies at the round-off
# floor of the stiff beam models: Newton stalls at relative errors of
# 1.2e-8 to 1.8e-8 (80 elements) and 1.1e-7 (320 elements) near t = 0.88 s
# and the step fails; 1e-6 clears that floor for every mesh.
NEWTON_RELATIVE_TOLERANCE = 1.0e-6

# What a cached reference depends on besides the problem and the step.
SETTINGS_ID = ("ga-index3", RHO_INFINITY, NEWTON_RELATIVE_TOLERANCE, "jac-per-step", "fixed-step")


def solver_settings(end_time, h, threads=1, sparse=True):
    """Generalized-α (index-3 constraints) with the fixed step h. Settings
    that differ from Exudyn's defaults:

    - spectralRadius = RHO_INFINITY;
    - newton.relativeTolerance = NEWTON_RELATIVE_TOLERANCE (default 1e-8;
      absoluteTolerance stays 1e-10);
    - newton.modifiedNewtonJacUpdatePerStep = True: a Jacobian at every step,
      modified Newton within it (the default keeps Jacobians across steps:
      8.4 instead of 3.9 Newton iterations per step, and slower, for 20
      elements at h = 1e-3);
    - adaptiveStep = False: every run is at the step h it is said to be at; a
      Newton failure fails the run (with the default, Exudyn halves the step
      and writes its sensors off the output times);
    - linearSolver.solverType: EigenSparse when `sparse`, else EXUdense;
    - no solution file; sensors every OUTPUT_PERIOD; verboseMode = 1 (its
      messages, captured, name the reason of a failure).
    """
    s = exu.SimulationSettings()
    ti = s.timeIntegration
    ti.endTime = end_time
    ti.numberOfSteps = steps_for(end_time, h)
    ti.verboseMode = 1
    ti.adaptiveStep = False
    ti.generalizedAlpha.spectralRadius = RHO_INFINITY
    ti.generalizedAlpha.useIndex2Constraints = False
    ti.generalizedAlpha.useNewmark = False
    ti.newton.relativeTolerance = NEWTON_RELATIVE_TOLERANCE
    ti.newton.useModifiedNewton = True
    ti.newton.modifiedNewtonJacUpdatePerStep = True
    s.linearSolver.solverType = exu.LinearSolverType.EigenSparse if sparse else exu.LinearSolverType.EXUdense
    s.parallel.numberOfThreads = threads
    s.solution.file.write = False
    s.solution.sensors.writePeriod = OUTPUT_PERIOD
    return s


def _solve(build, end_time, h, threads, sparse):
    t0 = time.perf_counter()
    SC, mbs, sensor = build()
    settings = solver_settings(end_time, h, threads, sparse)
    console = io.StringIO()
    t1 = time.perf_counter()
    try:
        with contextlib.redirect_stdout(console):
            mbs.SolveDynamic(settings, showHints=False)
        ok, message = True, ""
    except Exception as e:  # exudyn.SolverError and the like
        ok, message = False, _failure(console.getvalue(), str(e))
    t2 = time.perf_counter()
    it = mbs.sys["dynamicSolver"].it if "dynamicSolver" in mbs.sys else None
    run = Run(
        ok=ok,
        message=message,
        wall_solve=t2 - t1,
        wall_total=t2 - t0,
        steps=int(it.currentStepIndex) - 1 if it else 0,
        newton_iterations=int(it.newtonStepsCount) if it else 0,
        jacobians=int(it.newtonJacobiCount) if it else 0,
    )
    data = np.asarray(mbs.GetSensorStoredData(sensor))
    expected = np.arange(steps_for(end_time, OUTPUT_PERIOD) + 1) * OUTPUT_PERIOD
    if ok:
        if data.shape[0] != expected.size or np.abs(data[:, 0] - expected).max() > 1e-9:
            run.ok = False
            run.message = f"sensor times do not match the output times ({data.shape[0]} rows)"
        elif not np.all(np.isfinite(data[:, 1:])):
            run.ok = False
            run.message = "non-finite positions"
    run.times = data[:, 0] if data.size else np.zeros(0)
    run.positions = data[:, 1:4] if data.size else np.zeros((0, 3))
    return run


def _failure(console, error):
    """The last solver message that says why it stopped."""
    lines = [l.strip() for l in console.splitlines()]
    for key in ("stop solver", "convergence failed", "unsuccessfully"):
        found = [l for l in lines if key in l]
        if found:
            return found[-1]
    return error


# Linear solver per problem: EigenSparse for the beams (n = 20, h = 1e-3,
# Exudyn's default Newton settings: 2.6 s against 4.6 s dense), the dense
# solver for the 11 unknowns of the top (h = 3.125e-4: 0.17 s against 0.28 s
# sparse); measured on this machine.
PENDULUM_SPARSE = True
TOP_SPARSE = False


def run_pendulum(n, h, threads=1, sparse=PENDULUM_SPARSE):
    return _solve(lambda: pendulum_model(n), Pendulum.end_time, h, threads, sparse)


def run_top(h, threads=1, sparse=TOP_SPARSE):
    return _solve(top_model, HeavyTop.end_time, h, threads, sparse)


def version():
    return exu.__version__
