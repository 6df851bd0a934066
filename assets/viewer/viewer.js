// unfold view: the script of the page that `unfold view` writes
// (src/io/view, docs/viewer.md). The page holds, as text:
// - #manifest: JSON describing the run and where each array is in the data;
// - #data: the arrays, one zlib stream in base64 (src/io/view/pack.rs):
//   positions and colour fields quantised to 16-bit codes of their range
//   over the run, frame after frame as differences from the frame before,
//   low bytes then high bytes;
// - script[data-library]: three.js and uPlot, compressed the same way.
// It inflates them with the browser's DecompressionStream, builds the scene
// (beams and links as tubes, joints as spheres, bodies' shapes and panels
// as surfaces) and plays the frames against the time line.
//
// Address fragment (for links and tests): #t=0.5 or #t=end, #frame=12 or
// #frame=last, #field=M3 (or none), #history=energies.csv:kinetic or
// joints.csv:23:angle, #range=frame (colours over the step shown),
// #surfaces=see-through, #size=1 (tube size, log2 steps), #play. Without t
// or frame the page starts playing from the first frame.
//
// Errors are shown at the top of the page and recorded in the attribute
// data-errors of <html> and in the title; once drawn, <html> has
// data-state="ready", data-frame (the frame shown) and data-canvas (the
// 3-D view's rectangle in CSS pixels: left, top, width, height).
'use strict';

const errors = [];
function report(message) {
  errors.push(String(message));
  const box = document.getElementById('errors');
  if (box) {
    box.hidden = false;
    box.textContent = errors.join('\n');
  }
  document.documentElement.dataset.errors = String(errors.length);
  document.title = 'error: ' + errors[0];
}
window.addEventListener('error', (e) => {
  report(`${e.message} (${e.filename || 'page'}:${e.lineno || 0})`);
});
window.addEventListener('unhandledrejection', (e) => {
  const r = e.reason;
  report(r && r.stack ? r.stack : String(r));
});

// the largest code of a value; 65535 marks a missing one (pack.rs)
const TOP = 65534;
const MISSING = 65535;

/// The bytes of a base64 zlib stream.
async function inflate(base64) {
  const text = atob(base64.trim());
  const bytes = new Uint8Array(text.length);
  for (let i = 0; i < text.length; i++) bytes[i] = text.charCodeAt(i);
  const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream('deflate'));
  return new Uint8Array(await new Response(stream).arrayBuffer());
}

/// Runs the embedded libraries, in order.
async function loadLibraries() {
  for (const element of Array.from(document.querySelectorAll('script[data-library]'))) {
    const code = new TextDecoder().decode(await inflate(element.textContent));
    const script = document.createElement('script');
    script.textContent = code;
    document.head.appendChild(script); // runs it
    script.remove();
    element.remove();
  }
}

/// Numbers for labels: 4 significant digits.
function fmt(v) {
  if (v === null || v === undefined || !Number.isFinite(v)) return '–';
  const a = Math.abs(v);
  if (a !== 0 && (a >= 1e5 || a < 1e-3)) return v.toExponential(3);
  return String(Number(v.toPrecision(4)));
}

/// The arrays of the page's data (src/io/view/pack.rs).
class Data {
  constructor(manifest, bytes) {
    this.m = manifest;
    this.bytes = bytes;
  }

  /// Codes of frames written as differences between frames.
  frames(d) {
    const n = d.count;
    const w = d.width;
    const low = this.bytes.subarray(d.offset, d.offset + n);
    const high = this.bytes.subarray(d.offset + n, d.offset + 2 * n);
    const out = new Uint16Array(n);
    for (let i = 0; i < n; i++) {
      let v = low[i] | (high[i] << 8);
      if (i >= w) v = (v + out[i - w]) & 0xffff;
      out[i] = v;
    }
    return out;
  }

  u8(d) {
    return this.bytes.subarray(d.offset, d.offset + d.count);
  }

  i32(d) {
    return new Int32Array(this.bytes.buffer, this.bytes.byteOffset + d.offset, d.count);
  }

  f64(d) {
    return new Float64Array(this.bytes.buffer, this.bytes.byteOffset + d.offset, d.count);
  }
}

// colours of what is not coloured by a field, by kind of element
const KIND_COLOURS = {
  beam: 0x3f6fb0,
  'rigid body': 0xd39b3a,
  'point mass': 0xd39b3a,
  spring: 0xb0413e,
  joint: 0x2b2f36,
  'rolling disc': 0x2b2f36,
  'rigid link': 0x8a9099,
};
const SURFACE_COLOUR = 0x5f9e6e;
const OTHER_COLOUR = 0x6b7480;
const EVENT_COLOURS = {
  lock: '#c0392b',
  unlatch: '#8e44ad',
  impact: '#e67e22',
  contact: '#16a085',
  release: '#2980b9',
};

// viridis, for fields of one sign (9 stops)
const VIRIDIS = [
  [0.267, 0.005, 0.329], [0.283, 0.141, 0.458], [0.254, 0.265, 0.530],
  [0.207, 0.372, 0.553], [0.164, 0.471, 0.558], [0.128, 0.567, 0.551],
  [0.135, 0.659, 0.518], [0.267, 0.749, 0.441], [0.478, 0.821, 0.318],
  [0.741, 0.873, 0.150], [0.993, 0.906, 0.144],
];
// blue – light grey – red, for fields of both signs
const DIVERGING = [
  [0.230, 0.299, 0.754], [0.552, 0.690, 0.996], [0.866, 0.866, 0.866],
  [0.958, 0.604, 0.482], [0.706, 0.016, 0.150],
];

function ramp(stops, s) {
  const x = Math.min(Math.max(s, 0), 1) * (stops.length - 1);
  const i = Math.min(Math.floor(x), stops.length - 2);
  const f = x - i;
  const a = stops[i];
  const b = stops[i + 1];
  return [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2])];
}

/// The colour map of values in [lo, hi]: value → [r, g, b] in [0, 1];
/// symmetric about zero for a range of both signs.
function colourMap(lo, hi) {
  if (lo < 0 && hi > 0) {
    const m = Math.max(-lo, hi);
    return (v) => ramp(DIVERGING, 0.5 + (0.5 * v) / m);
  }
  if (!(hi > lo)) return () => ramp(VIRIDIS, 0.5);
  return (v) => ramp(VIRIDIS, (v - lo) / (hi - lo));
}

/// VTK's faces of a hexahedron (vtkHexahedron).
const HEX_FACES = [
  [0, 4, 7, 3], [1, 2, 6, 5], [0, 1, 5, 4], [3, 7, 6, 2], [0, 3, 2, 1], [4, 5, 6, 7],
];

class Viewer {
  constructor(data) {
    const m = data.m;
    this.data = data;
    this.m = m;
    this.times = m.frames.times;
    this.nFrames = this.times.length;
    this.nPoints = m.points.count;
    this.t0 = this.times[0];
    this.t1 = this.times[this.nFrames - 1];
    this.frame = 0;
    this.time = this.t0;
    this.playing = false;
    this.dirty = true;
    this.sizeScale = 1;

    // positions of every frame, decoded
    const codes = data.frames(m.points.positions);
    const { lo, hi } = m.points;
    this.positions = new Float32Array(codes.length);
    for (let i = 0; i < codes.length; i++) {
      const c = i % 3;
      this.positions[i] = lo[c] + (codes[i] / TOP) * (hi[c] - lo[c]);
    }
    this.centre = [0, 1, 2].map((c) => 0.5 * (lo[c] + hi[c]));
    this.diagonal = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 1;

    // cells
    this.types = data.u8(m.cells.types);
    this.offsets = data.i32(m.cells.offsets);
    this.connectivity = data.i32(m.cells.connectivity);
    this.kind = data.i32(m.cells.kind);
    this.elementId = data.f64(m.cells.element_id);
    this.kindName = (c) => m.kinds[String(this.kind[c])] || 'element';
    this.fields = m.fields;
    this.fieldCodes = new Map();
    this.field = -1;
    this.rangeOfFrame = false;

    this.classify();
    this.buildScene();
  }

  /// The points of cell `c`.
  cellPoints(c) {
    const start = c === 0 ? 0 : this.offsets[c - 1];
    return this.connectivity.subarray(start, this.offsets[c]);
  }

  /// Tubes, spheres, surfaces and their edges, from the cells.
  classify() {
    const tubes = []; // [cell, a, b, radius, colour]
    const spheres = []; // [cell or -1, point, radius, colour]
    const triangles = []; // [cell, p, q, r, colour of its kind]
    const faces = []; // polygons (point lists) for the edges
    const beamPoint = new Map(); // point → a beam cell through it
    const nCells = this.types.length;
    for (let c = 0; c < nCells; c++) {
      const p = this.cellPoints(c);
      const name = this.kindName(c);
      const type = this.types[c];
      if (type === 3) {
        let r = 0.45;
        if (name === 'beam') r = 1.0;
        else if (name === 'rigid body') r = 1.2;
        else if (name === 'spring') r = 0.35;
        tubes.push([c, p[0], p[1], r, KIND_COLOURS[name] ?? OTHER_COLOUR]);
        if (name === 'beam') {
          for (const q of [p[0], p[1]]) if (!beamPoint.has(q)) beamPoint.set(q, c);
        }
      } else if (type === 1) {
        let r = 2.0;
        if (name === 'rigid body' || name === 'point mass') r = 2.6;
        else if (name === 'spring') r = 1.2;
        spheres.push([c, p[0], r, KIND_COLOURS[name] ?? OTHER_COLOUR]);
      } else if (type === 5 || type === 7 || type === 9) {
        faces.push([c, Array.from(p)]);
      } else if (type === 12) {
        for (const f of HEX_FACES) faces.push([c, f.map((k) => p[k])]);
      }
    }
    for (const [c, poly] of faces) {
      const hex = this.kindName(c) === 'rigid body' ? KIND_COLOURS['rigid body'] : SURFACE_COLOUR;
      for (let k = 1; k + 1 < poly.length; k++) triangles.push([c, poly[0], poly[k], poly[k + 1], hex]);
    }
    // spheres at the beams' nodes join their tubes
    for (const [point, c] of beamPoint) spheres.push([c, point, 1.0, KIND_COLOURS.beam, true]);
    this.tubes = tubes;
    this.spheres = spheres;
    this.triangles = triangles;
    this.edges = this.featureEdges(faces);
  }

  /// Edges of the surfaces to outline: those of one face, and those where
  /// faces meet at more than 25° (a box's edges, not a cylinder's facets).
  featureEdges(faces) {
    const pos = this.positions;
    const normal = (poly) => {
      const n = [0, 0, 0];
      for (let k = 0; k < poly.length; k++) {
        const a = 3 * poly[k];
        const b = 3 * poly[(k + 1) % poly.length];
        n[0] += pos[a + 1] * pos[b + 2] - pos[a + 2] * pos[b + 1];
        n[1] += pos[a + 2] * pos[b] - pos[a] * pos[b + 2];
        n[2] += pos[a] * pos[b + 1] - pos[a + 1] * pos[b];
      }
      const l = Math.hypot(n[0], n[1], n[2]);
      return l > 0 ? n.map((v) => v / l) : null;
    };
    const byEdge = new Map();
    for (const [, poly] of faces) {
      const n = normal(poly);
      for (let k = 0; k < poly.length; k++) {
        const a = poly[k];
        const b = poly[(k + 1) % poly.length];
        const key = a < b ? `${a},${b}` : `${b},${a}`;
        if (!byEdge.has(key)) byEdge.set(key, { a, b, normals: [] });
        byEdge.get(key).normals.push(n);
      }
    }
    const cos = Math.cos((25 * Math.PI) / 180);
    const edges = [];
    for (const { a, b, normals } of byEdge.values()) {
      let feature = normals.length === 1;
      for (let i = 0; i < normals.length && !feature; i++) {
        for (let j = i + 1; j < normals.length && !feature; j++) {
          const u = normals[i];
          const v = normals[j];
          if (!u || !v || Math.abs(u[0] * v[0] + u[1] * v[1] + u[2] * v[2]) < cos) feature = true;
        }
      }
      if (feature) edges.push(a, b);
    }
    return edges;
  }

  buildScene() {
    const T = THREE;
    const view = document.getElementById('view');
    this.renderer = new T.WebGLRenderer({ antialias: true });
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    this.renderer.domElement.className = 'scene';
    view.prepend(this.renderer.domElement);
    this.scene = new T.Scene();
    this.scene.background = new T.Color(0xf7f8fa);
    this.camera = new T.PerspectiveCamera(35, 1, this.diagonal * 1e-3, this.diagonal * 100);
    this.camera.up.set(0, 0, 1);
    this.scene.add(new T.HemisphereLight(0xffffff, 0x8d8a80, 1.6));
    this.headlight = new T.DirectionalLight(0xffffff, 1.6);
    this.camera.add(this.headlight);
    this.headlight.position.set(0.3, 0.6, 1);
    this.scene.add(this.camera);
    this.controls = new T.OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener('change', () => (this.dirty = true));

    // tubes: open cylinders from y = 0 to 1, placed per frame
    const cylinder = new T.CylinderGeometry(1, 1, 1, 14, 1, true);
    cylinder.translate(0, 0.5, 0);
    const material = new T.MeshLambertMaterial({ color: 0xffffff });
    this.tubeMesh = new T.InstancedMesh(cylinder, material, Math.max(this.tubes.length, 1));
    this.tubeMesh.count = this.tubes.length;
    const sphere = new T.SphereGeometry(1, 16, 12);
    this.sphereMesh = new T.InstancedMesh(sphere, material, Math.max(this.spheres.length, 1));
    this.sphereMesh.count = this.spheres.length;
    for (const mesh of [this.tubeMesh, this.sphereMesh]) {
      mesh.instanceMatrix.setUsage(T.DynamicDrawUsage);
      mesh.frustumCulled = false;
      this.scene.add(mesh);
    }

    // surfaces: one triangle soup, coloured per vertex
    const n = 3 * this.triangles.length;
    this.surfaceGeometry = new T.BufferGeometry();
    this.surfaceGeometry.setAttribute('position', new T.BufferAttribute(new Float32Array(3 * n), 3));
    this.surfaceGeometry.setAttribute('color', new T.BufferAttribute(new Float32Array(3 * n), 3));
    this.surfaceMesh = new T.Mesh(
      this.surfaceGeometry,
      new T.MeshLambertMaterial({
        vertexColors: true,
        side: T.DoubleSide,
        polygonOffset: true,
        polygonOffsetFactor: 1,
        polygonOffsetUnits: 1,
      }),
    );
    this.surfaceMesh.frustumCulled = false;
    this.scene.add(this.surfaceMesh);
    this.edgeGeometry = new T.BufferGeometry();
    this.edgeGeometry.setAttribute('position', new T.BufferAttribute(new Float32Array(3 * this.edges.length), 3));
    this.edgeLines = new T.LineSegments(this.edgeGeometry, new T.LineBasicMaterial({ color: 0x30363d }));
    this.edgeLines.frustumCulled = false;
    this.scene.add(this.edgeLines);

    this.matrix = new T.Matrix4();
    this.quaternion = new T.Quaternion();
    this.vector = new T.Vector3();
    this.scale = new T.Vector3();
    this.up = new T.Vector3(0, 1, 0);
    this.colour = new T.Color();
    this.white = new T.Color(0xffffff);
    this.resize();
    this.fit('iso');
  }

  resize() {
    const view = document.getElementById('view');
    const w = Math.max(view.clientWidth, 1);
    const h = Math.max(view.clientHeight, 1);
    this.renderer.setSize(w, h);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.dirty = true;
  }

  /// Puts the camera so that the whole run is in view, from `direction`.
  fit(direction) {
    const d = {
      iso: [1.0, -1.35, 0.85],
      x: [1, 0, 0],
      y: [0, -1, 0],
      z: [0, 0, 1],
    }[direction];
    const l = Math.hypot(d[0], d[1], d[2]);
    const distance = (0.5 * this.diagonal) / Math.tan((this.camera.fov * Math.PI) / 360);
    const [cx, cy, cz] = this.centre;
    this.camera.up.set(0, direction === 'z' ? 1 : 0, direction === 'z' ? 0 : 1);
    this.camera.position.set(cx + (d[0] / l) * distance, cy + (d[1] / l) * distance, cz + (d[2] / l) * distance);
    this.controls.target.set(cx, cy, cz);
    this.controls.update();
    this.dirty = true;
  }

  /// The codes of field `k` (decoded once).
  codesOf(k) {
    if (!this.fieldCodes.has(k)) this.fieldCodes.set(k, this.data.frames(this.fields[k].values));
    return this.fieldCodes.get(k);
  }

  setField(k) {
    this.field = k;
    if (k >= 0) {
      const f = this.fields[k];
      this.mask = f.mask ? this.data.u8(f.mask) : null;
    }
    this.dirty = true;
  }

  /// The range of the colours: the field's over the run, or over the
  /// cells (points) that carry it at the frame shown.
  colourRange() {
    const f = this.fields[this.field];
    if (!this.rangeOfFrame) return [f.min, f.max];
    const codes = this.codesOf(this.field);
    const width = f.on === 'cells' ? this.types.length : this.nPoints;
    let lo = MISSING;
    let hi = -1;
    for (let i = 0; i < width; i++) {
      if (f.on === 'cells' && this.mask && !this.mask[i]) continue;
      const c = codes[this.frame * width + i];
      if (c === MISSING) continue;
      if (c < lo) lo = c;
      if (c > hi) hi = c;
    }
    if (hi < 0) return [f.min, f.max];
    const value = (c) => f.min + (c / TOP) * (f.max - f.min);
    return [value(lo), value(hi)];
  }

  drawLegend(lo, hi) {
    const legend = document.getElementById('legend');
    if (this.field < 0) {
      legend.hidden = true;
      return;
    }
    const f = this.fields[this.field];
    legend.hidden = false;
    const canvas = document.getElementById('legend-bar');
    const ctx = canvas.getContext('2d');
    for (let x = 0; x < canvas.width; x++) {
      const [r, g, b] = this.map(lo + (x / (canvas.width - 1)) * (hi - lo));
      ctx.fillStyle = `rgb(${255 * r},${255 * g},${255 * b})`;
      ctx.fillRect(x, 0, 1, canvas.height);
    }
    // round-off about zero (a joint's load at rest, 1e-37) shows as 0
    const tiny = 1e-9 * Math.max(Math.abs(lo), Math.abs(hi));
    document.getElementById('legend-min').textContent = fmt(Math.abs(lo) < tiny ? 0 : lo);
    document.getElementById('legend-max').textContent = fmt(Math.abs(hi) < tiny ? 0 : hi);
    document.getElementById('legend-name').textContent = f.name + (this.rangeOfFrame ? ' (this step)' : '');
  }

  /// The colour of cell `c` or point `p` at the frame shown, or null for
  /// the colour of its kind.
  fieldColour(c, p) {
    if (this.field < 0) return null;
    const f = this.fields[this.field];
    const codes = this.codesOf(this.field);
    let code;
    if (f.on === 'cells') {
      if (c < 0 || (this.mask && !this.mask[c])) return null;
      code = codes[this.frame * this.types.length + c];
    } else {
      if (p < 0) return null;
      code = codes[this.frame * this.nPoints + p];
    }
    return code === MISSING ? null : this.map(f.min + (code / TOP) * (f.max - f.min));
  }

  /// The value of the field shown at cell `c` or point `p`.
  fieldValue(c, p) {
    if (this.field < 0) return null;
    const f = this.fields[this.field];
    const codes = this.codesOf(this.field);
    const i = f.on === 'cells' ? this.frame * this.types.length + c : this.frame * this.nPoints + p;
    if ((f.on === 'cells' && (c < 0 || (this.mask && !this.mask[c]))) || (f.on === 'points' && p < 0)) return null;
    const code = codes[i];
    return code === MISSING ? null : f.min + (code / TOP) * (f.max - f.min);
  }

  /// Colour of a kind, pale when another field colours the view.
  kindColour(hex) {
    this.colour.setHex(hex);
    if (this.field >= 0) this.colour.lerp(this.white, 0.55);
    return this.colour;
  }

  point(p) {
    const at = 3 * (this.frame * this.nPoints + p);
    return this.vector.set(this.positions[at], this.positions[at + 1], this.positions[at + 2]);
  }

  /// Draws the frame shown.
  update() {
    if (this.field >= 0) {
      const [lo, hi] = this.colourRange();
      this.map = colourMap(lo, hi);
      this.drawLegend(lo, hi);
    } else {
      this.drawLegend();
    }
    const base = 0.004 * this.diagonal * this.sizeScale;
    const pos = this.positions;
    const frameAt = 3 * this.frame * this.nPoints;
    const onPoints = this.field >= 0 && this.fields[this.field].on === 'points';

    // tubes
    const dir = new THREE.Vector3();
    this.tubes.forEach(([c, a, b, r, hex], i) => {
      const ia = frameAt + 3 * a;
      const ib = frameAt + 3 * b;
      dir.set(pos[ib] - pos[ia], pos[ib + 1] - pos[ia + 1], pos[ib + 2] - pos[ia + 2]);
      const length = dir.length();
      if (length > 1e-9 * this.diagonal) {
        this.quaternion.setFromUnitVectors(this.up, dir.divideScalar(length));
      } else {
        this.quaternion.identity();
      }
      this.vector.set(pos[ia], pos[ia + 1], pos[ia + 2]);
      this.scale.set(base * r, length, base * r);
      this.matrix.compose(this.vector, this.quaternion, this.scale);
      this.tubeMesh.setMatrixAt(i, this.matrix);
      let rgb;
      if (onPoints) {
        const u = this.fieldColour(-1, a);
        const v = this.fieldColour(-1, b);
        rgb = u && v ? [0, 1, 2].map((k) => 0.5 * (u[k] + v[k])) : null;
      } else {
        rgb = this.fieldColour(c, -1);
      }
      this.tubeMesh.setColorAt(i, rgb ? this.colour.setRGB(rgb[0], rgb[1], rgb[2]) : this.kindColour(hex));
    });
    // spheres
    this.quaternion.identity();
    this.spheres.forEach(([c, p, r, hex], i) => {
      const at = frameAt + 3 * p;
      this.vector.set(pos[at], pos[at + 1], pos[at + 2]);
      this.scale.set(base * r, base * r, base * r);
      this.matrix.compose(this.vector, this.quaternion, this.scale);
      this.sphereMesh.setMatrixAt(i, this.matrix);
      const rgb = onPoints ? this.fieldColour(-1, p) : this.fieldColour(c, -1);
      this.sphereMesh.setColorAt(i, rgb ? this.colour.setRGB(rgb[0], rgb[1], rgb[2]) : this.kindColour(hex));
    });
    for (const mesh of [this.tubeMesh, this.sphereMesh]) {
      mesh.instanceMatrix.needsUpdate = true;
      if (mesh.instanceColor) mesh.instanceColor.needsUpdate = true;
      mesh.boundingSphere = null;
    }

    // surfaces
    const sp = this.surfaceGeometry.attributes.position.array;
    const sc = this.surfaceGeometry.attributes.color.array;
    let v = 0;
    for (const [c, p0, p1, p2, hex] of this.triangles) {
      const cellRgb = onPoints ? null : this.fieldColour(c, -1);
      for (const p of [p0, p1, p2]) {
        const at = frameAt + 3 * p;
        sp[3 * v] = pos[at];
        sp[3 * v + 1] = pos[at + 1];
        sp[3 * v + 2] = pos[at + 2];
        const rgb = onPoints ? this.fieldColour(-1, p) : cellRgb;
        const col = rgb ? this.colour.setRGB(rgb[0], rgb[1], rgb[2]) : this.kindColour(hex);
        sc[3 * v] = col.r;
        sc[3 * v + 1] = col.g;
        sc[3 * v + 2] = col.b;
        v++;
      }
    }
    this.surfaceGeometry.attributes.position.needsUpdate = true;
    this.surfaceGeometry.attributes.color.needsUpdate = true;
    this.surfaceGeometry.computeVertexNormals();
    this.surfaceGeometry.boundingSphere = null;
    const ep = this.edgeGeometry.attributes.position.array;
    this.edges.forEach((p, k) => {
      const at = frameAt + 3 * p;
      ep[3 * k] = pos[at];
      ep[3 * k + 1] = pos[at + 1];
      ep[3 * k + 2] = pos[at + 2];
    });
    this.edgeGeometry.attributes.position.needsUpdate = true;
    this.dirty = true;
  }

  render() {
    this.renderer.render(this.scene, this.camera);
    this.dirty = false;
  }

  /// The element or point under the pointer at (x, y) in the canvas, as
  /// text.
  pick(x, y) {
    const T = THREE;
    const rect = this.renderer.domElement.getBoundingClientRect();
    const ndc = new T.Vector2(((x - rect.left) / rect.width) * 2 - 1, -((y - rect.top) / rect.height) * 2 + 1);
    const ray = new T.Raycaster();
    ray.setFromCamera(ndc, this.camera);
    for (const mesh of [this.tubeMesh, this.sphereMesh]) mesh.computeBoundingSphere();
    this.surfaceGeometry.computeBoundingSphere();
    const hits = ray.intersectObjects([this.sphereMesh, this.tubeMesh, this.surfaceMesh], false);
    if (!hits.length) return null;
    const hit = hits[0];
    let c = -1;
    let p = -1;
    if (hit.object === this.tubeMesh) {
      [c] = this.tubes[hit.instanceId];
    } else if (hit.object === this.sphereMesh) {
      const s = this.spheres[hit.instanceId];
      if (!s[4]) c = s[0];
      p = s[1];
    } else {
      const tri = this.triangles[hit.faceIndex];
      c = tri[0];
      p = tri[1];
    }
    const what = c >= 0 ? `${this.kindName(c)} ${this.elementId[c]}` : `point ${p}`;
    const value = this.fieldValue(c, p);
    return this.field >= 0 && value !== null ? `${what}: ${this.fields[this.field].name} = ${fmt(value)}` : what;
  }
}

/// The time-history plot and its choices.
class History {
  constructor(app) {
    this.app = app;
    const m = app.data.m;
    this.files = m.histories;
    this.steps = m.steps;
    this.fileSelect = document.getElementById('history-file');
    this.entitySelect = document.getElementById('history-entity');
    this.columnSelect = document.getElementById('history-column');
    this.plot = null;
    if (!this.files.length) {
      document.getElementById('chart').textContent = 'no histories in these results';
      for (const s of [this.fileSelect, this.entitySelect, this.columnSelect]) s.hidden = true;
      return;
    }
    this.files.forEach((f, k) => this.fileSelect.add(new Option(f.file, k)));
    this.fileSelect.onchange = () => this.chooseFile(Number(this.fileSelect.value));
    this.entitySelect.onchange = () => this.chooseEntity(Number(this.entitySelect.value));
    this.columnSelect.onchange = () => this.draw();
  }

  chooseFile(k, entity, column) {
    this.fileSelect.value = k;
    const f = this.files[k];
    this.entitySelect.innerHTML = '';
    f.entities.forEach((e, i) => {
      this.entitySelect.add(new Option(f.entity ? `${f.entity} ${e.id}${e.type ? ` (${e.type})` : ''}` : '–', i));
    });
    this.entitySelect.hidden = !f.entity;
    let i = 0;
    if (entity !== undefined) i = Math.max(0, f.entities.findIndex((e) => String(e.id) === String(entity)));
    this.chooseEntity(i, column);
  }

  chooseEntity(i, column) {
    this.entitySelect.value = i;
    const e = this.files[Number(this.fileSelect.value)].entities[i];
    const previous = column ?? this.columnSelect.value;
    this.columnSelect.innerHTML = '';
    e.series.forEach((s) => this.columnSelect.add(new Option(s.column, s.column)));
    if (e.series.some((s) => s.column === previous)) this.columnSelect.value = previous;
    this.draw();
  }

  /// Chooses a series by `file:column` or `file:entity:column`, else a
  /// default one.
  choose(spec) {
    if (!this.files.length) return;
    let parts = spec ? spec.split(':') : [];
    let k = parts.length ? this.files.findIndex((f) => f.file === parts[0] || f.file === `${parts[0]}.csv`) : -1;
    if (k < 0) {
      k = this.files.findIndex((f) => f.file === 'energies.csv');
      parts = k >= 0 ? ['energies.csv', 'kinetic'] : [];
    }
    if (k < 0) {
      k = 0;
      parts = [];
    }
    const f = this.files[k];
    if (f.entity) this.chooseFile(k, parts[1], parts[2]);
    else this.chooseFile(k, undefined, parts[1]);
  }

  draw() {
    const f = this.files[Number(this.fileSelect.value)];
    const e = f.entities[Number(this.entitySelect.value)];
    const s = e.series.find((x) => x.column === this.columnSelect.value) || e.series[0];
    const codes = this.app.data.frames(s.values);
    const y = Array.from(codes, (c) => {
      if (c === MISSING) return null;
      const v = s.min + (c / TOP) * (s.max - s.min);
      return s.log ? 10 ** v : v;
    });
    const label = `${s.column}${f.entity ? ` (${f.entity} ${e.id}${e.type ? `, ${e.type}` : ''})` : ''}`;
    const chart = document.getElementById('chart');
    if (this.plot) this.plot.destroy();
    const app = this.app;
    const marks = (u) => {
      const ctx = u.ctx;
      const top = u.bbox.top;
      const height = u.bbox.height;
      ctx.save();
      for (const ev of app.events) {
        const x = u.valToPos(ev.time, 'x', true);
        ctx.strokeStyle = EVENT_COLOURS[ev.kind] || '#7f8c8d';
        ctx.setLineDash([4, 3]);
        ctx.lineWidth = 1;
        ctx.beginPath();
        ctx.moveTo(x, top);
        ctx.lineTo(x, top + height);
        ctx.stroke();
      }
      const x = u.valToPos(app.viewer.time, 'x', true);
      ctx.setLineDash([]);
      ctx.strokeStyle = '#c0392b';
      ctx.lineWidth = 2;
      ctx.beginPath();
      ctx.moveTo(x, top);
      ctx.lineTo(x, top + height);
      ctx.stroke();
      ctx.restore();
    };
    this.plot = new uPlot(
      {
        width: Math.max(chart.clientWidth, 200),
        height: 260,
        legend: { show: true },
        scales: { x: { time: false }, y: { distr: s.log ? 3 : 1 } },
        series: [
          { label: app.data.m.time_name, value: (u, v) => fmt(v) },
          { label, stroke: '#3f6fb0', width: 1.5, value: (u, v) => fmt(v), points: { show: y.length < 120 } },
        ],
        axes: [{ values: (u, vals) => vals.map(fmt) }, { size: 60, values: (u, vals) => vals.map(fmt) }],
        hooks: { draw: [marks] },
      },
      [this.steps, y],
      chart,
    );
    // a click (not a drag) on the plot shows that time
    let down = null;
    this.plot.over.addEventListener('mousedown', (ev) => (down = ev.offsetX));
    this.plot.over.addEventListener('mouseup', (ev) => {
      if (down !== null && Math.abs(ev.offsetX - down) < 3) app.setTime(this.plot.posToVal(ev.offsetX, 'x'));
      down = null;
    });
    this.spec = `${f.file}:${f.entity ? `${e.id}:` : ''}${s.column}`;
  }

  redraw() {
    if (this.plot) this.plot.redraw(false, false);
  }
}

class App {
  constructor(data) {
    this.data = data;
    const m = data.m;
    this.viewer = new Viewer(data);
    this.events = m.events;
    this.history = new History(this);
    this.slider = document.getElementById('time');
    this.slider.min = this.viewer.t0;
    this.slider.max = this.viewer.t1;
    this.slider.oninput = () => this.setTime(Number(this.slider.value));
    document.getElementById('play').onclick = () => this.togglePlay();

    // colour fields
    const select = document.getElementById('field');
    select.add(new Option('kind of element', -1));
    m.fields.forEach((f, k) => {
      const o = new Option(`${f.name} (${f.on === 'cells' ? 'cells' : 'points'})`, k);
      o.title = f.source;
      select.add(o);
    });
    select.onchange = () => {
      this.viewer.setField(Number(select.value));
      this.viewer.update();
    };
    this.fieldSelect = select;
    const range = document.getElementById('range');
    range.onchange = () => {
      this.viewer.rangeOfFrame = range.value === 'frame';
      this.viewer.update();
    };
    const surfaces = document.getElementById('surfaces');
    surfaces.onchange = () => {
      const material = this.viewer.surfaceMesh.material;
      const see = surfaces.value === 'see-through';
      material.transparent = see;
      material.opacity = see ? 0.35 : 1;
      material.depthWrite = !see;
      material.needsUpdate = true;
      this.viewer.dirty = true;
    };
    const size = document.getElementById('size');
    size.oninput = () => {
      this.viewer.sizeScale = 2 ** Number(size.value);
      this.viewer.update();
    };
    this.sizeInput = size;
    for (const d of ['iso', 'x', 'y', 'z']) document.getElementById(`view-${d}`).onclick = () => this.viewer.fit(d);

    this.drawEvents();
    this.describe();
    window.addEventListener('resize', () => {
      this.viewer.resize();
      if (this.history.plot) this.history.plot.setSize({ width: Math.max(document.getElementById('chart').clientWidth, 200), height: 260 });
    });
    window.addEventListener('keydown', (e) => {
      if (e.target && (e.target.tagName === 'SELECT' || e.target.tagName === 'INPUT')) return;
      if (e.key === ' ') {
        this.togglePlay();
        e.preventDefault();
      } else if (e.key === 'ArrowRight' || e.key === 'ArrowLeft') {
        const f = Math.min(Math.max(this.viewer.frame + (e.key === 'ArrowRight' ? 1 : -1), 0), this.viewer.nFrames - 1);
        this.setTime(this.viewer.times[f]);
      }
    });
    // what is under the pointer
    const readout = document.getElementById('readout');
    let pending = null;
    this.viewer.renderer.domElement.addEventListener('pointermove', (e) => {
      if (pending) return;
      pending = requestAnimationFrame(() => {
        pending = null;
        const text = this.viewer.pick(e.clientX, e.clientY);
        readout.hidden = !text;
        readout.textContent = text || '';
      });
    });
  }

  describe() {
    const m = this.data.m;
    const status = document.getElementById('status');
    const parts = [];
    if (m.model) parts.push(m.model);
    if (m.status) parts.push(`status ${m.status}${m.message ? `: ${m.message}` : ''}`);
    parts.push(`${m.steps.length} output steps`);
    if (m.frames.steps.length < m.steps.length) parts.push(`${m.frames.steps.length} frames`);
    status.textContent = parts.join(' · ');
  }

  drawEvents() {
    const marks = document.getElementById('event-marks');
    const list = document.getElementById('event-list');
    const span = this.viewer.t1 - this.viewer.t0 || 1;
    for (const ev of this.events) {
      const mark = document.createElement('span');
      mark.style.left = `${(100 * (ev.time - this.viewer.t0)) / span}%`;
      mark.style.background = EVENT_COLOURS[ev.kind] || '#7f8c8d';
      mark.title = `t = ${fmt(ev.time)}: ${ev.label}`;
      mark.onclick = () => this.setTime(ev.time);
      marks.appendChild(mark);
      const item = document.createElement('li');
      item.textContent = `t = ${fmt(ev.time)}: ${ev.label}`;
      item.style.color = EVENT_COLOURS[ev.kind] || '#444';
      item.onclick = () => this.setTime(ev.time);
      list.appendChild(item);
    }
    if (!this.events.length) list.outerHTML = '<p>none</p>';
  }

  /// Shows the last frame at or before `t`.
  setTime(t) {
    const v = this.viewer;
    t = Math.min(Math.max(t, v.t0), v.t1);
    let lo = 0;
    let hi = v.nFrames - 1;
    while (lo < hi) {
      const mid = (lo + hi + 1) >> 1;
      if (v.times[mid] <= t * (1 + 1e-12) + 1e-300) lo = mid;
      else hi = mid - 1;
    }
    v.time = t;
    if (lo !== v.frame || v.dirty) {
      v.frame = lo;
      v.update();
    }
    this.slider.value = t;
    const step = this.data.m.frames.steps[lo];
    document.getElementById('clock').textContent = `${this.data.m.time_name} ${fmt(t)} · step ${step}`;
    document.documentElement.dataset.frame = String(lo);
    this.history.redraw();
  }

  togglePlay() {
    const v = this.viewer;
    v.playing = !v.playing && v.t1 > v.t0;
    document.getElementById('play').textContent = v.playing ? '❚❚' : '▶';
    if (v.playing && v.time >= v.t1) this.setTime(v.t0);
    this.last = null;
  }

  /// Simulated time per second of playback.
  rate() {
    const s = document.getElementById('speed').value;
    if (s === 'real') return 1;
    if (s === 'slow') return 0.1;
    return (this.viewer.t1 - this.viewer.t0) / Number(s);
  }

  loop(now) {
    const v = this.viewer;
    if (v.playing) {
      if (this.last !== null && this.last !== undefined) {
        const t = v.time + ((now - this.last) / 1000) * this.rate();
        this.setTime(t);
        if (t >= v.t1) this.togglePlay();
      }
      this.last = now;
    }
    if (v.dirty) v.render();
    requestAnimationFrame((n) => this.loop(n));
  }

  /// Applies the address fragment (see the top of this file).
  start() {
    const params = new URLSearchParams(location.hash.replace(/^#/, ''));
    const v = this.viewer;
    const field = params.get('field');
    if (field !== null) {
      const k = this.data.m.fields.findIndex((f) => f.name === field);
      this.fieldSelect.value = k;
      v.setField(k);
    }
    if (params.get('range') === 'frame') {
      document.getElementById('range').value = 'frame';
      v.rangeOfFrame = true;
    }
    if (params.get('surfaces') === 'see-through') {
      const surfaces = document.getElementById('surfaces');
      surfaces.value = 'see-through';
      surfaces.onchange();
    }
    if (params.get('size') !== null) {
      this.sizeInput.value = params.get('size');
      v.sizeScale = 2 ** Number(params.get('size'));
    }
    this.history.choose(params.get('history'));
    let t = v.t0;
    const fixed = params.get('t') ?? params.get('frame');
    if (params.get('t') !== null) t = params.get('t') === 'end' ? v.t1 : Number(params.get('t'));
    if (params.get('frame') !== null) {
      const f = params.get('frame') === 'last' ? v.nFrames - 1 : Number(params.get('frame'));
      t = v.times[Math.min(Math.max(f, 0), v.nFrames - 1)];
    }
    v.dirty = true;
    this.setTime(t);
    v.render();
    document.getElementById('loading').remove();
    if (fixed === null || params.has('play')) this.togglePlay();
    const title = this.data.m.title || this.data.m.directory;
    if (!errors.length) document.title = `${title} – unfold view`;
    const r = v.renderer.domElement.getBoundingClientRect();
    document.documentElement.dataset.canvas = [r.left, r.top, r.width, r.height].map(Math.round).join(',');
    document.documentElement.dataset.state = 'ready';
    requestAnimationFrame((n) => this.loop(n));
  }
}

async function main() {
  if (typeof DecompressionStream === 'undefined') {
    throw new Error('this browser cannot inflate the page (no DecompressionStream: Chrome 80, Firefox 113, Safari 16.4 or newer have it)');
  }
  await loadLibraries();
  const manifest = JSON.parse(document.getElementById('manifest').textContent);
  const dataElement = document.getElementById('data');
  const bytes = await inflate(dataElement.textContent);
  dataElement.remove();
  const app = new App(new Data(manifest, bytes));
  app.start();
  window.unfoldView = app;
}

main().catch((e) => report(e && e.stack ? e.stack : String(e)));
