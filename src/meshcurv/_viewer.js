// meshcurv viewer: the script of the pages written by meshcurv.viewer.write_html.
// Plain WebGL2, no library, nothing fetched: the page carries its data in <script> blocks
// (base64 of little-endian typed arrays, described by the JSON block "meshcurv-meta").
// The page's state (field, limits, directions, view, a probe) can be set by the URL hash:
//   page.html#field=gaussian&lo=-0.01&hi=0.01&directions=both&elevation=20&azimuth=-30&zoom=1.5&probe=400,300
// The data-* attributes of #status report "ok" or the error, the time to the first frame and the
// probe's reading (for headless tests); an error also shows in the tab's title.
"use strict";

(function () {
  const statusElement = document.getElementById("status");
  const startedAt = performance.now();

  let pageTitle = "meshcurv viewer";

  function report(state, text, data) {  // the tab shows the mesh's name, or what went wrong
    document.title = state === "ok" ? `${pageTitle} - meshcurv viewer` : `meshcurv viewer: ${state}` + (text ? ` | ${text}` : "");
    statusElement.dataset.state = state;
    statusElement.textContent = text || state;
    for (const [key, value] of Object.entries(data || {})) statusElement.dataset[key] = String(value);
  }

  function fail(error) {
    const message = error && error.message ? error.message : String(error);
    report("error", message);
    statusElement.classList.add("error");
  }

  window.addEventListener("error", (event) => fail(event.error || event.message));
  window.addEventListener("unhandledrejection", (event) => fail(event.reason));

  // ---- data -------------------------------------------------------------------------------------

  const TYPES = { float32: Float32Array, uint32: Uint32Array, uint8: Uint8Array, int8: Int8Array };

  function base64Bytes(id) {
    const text = document.getElementById(id).textContent;
    if (typeof Uint8Array.fromBase64 === "function") return Uint8Array.fromBase64(text.trim());
    const binary = atob(text.trim());
    const bytes = new Uint8Array(binary.length);
    for (let i = 0; i < binary.length; i++) bytes[i] = binary.charCodeAt(i);
    return bytes;
  }

  async function inflate(bytes) {
    const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("deflate"));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  }

  async function readArray(spec) {
    let bytes = base64Bytes(spec.id);
    if (spec.compression === "deflate") bytes = await inflate(bytes);
    const Type = TYPES[spec.dtype];
    const count = spec.shape.reduce((a, b) => a * b, 1);
    if (bytes.byteLength !== count * Type.BYTES_PER_ELEMENT) {
      throw new Error(`array ${spec.id}: ${bytes.byteLength} bytes, expected ${count * Type.BYTES_PER_ELEMENT}`);
    }
    const array = new Type(bytes.buffer, bytes.byteOffset, count);
    if (spec.delta) {  // faces stored as differences of consecutive indices (mod 2^32)
      for (let i = 1; i < count; i++) array[i] = (array[i] + array[i - 1]) >>> 0;
    }
    return array;
  }

  function rendererName(gl) {  // the real renderer (SwiftShader, a GPU), where the browser tells it
    const info = gl.getExtension("WEBGL_debug_renderer_info");
    return info ? gl.getParameter(info.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER);
  }

  function littleEndian() {
    return new Uint8Array(new Uint32Array([1]).buffer)[0] === 1;
  }

  // ---- fields -----------------------------------------------------------------------------------

  const FIELD_FORMULAS = {
    k_min: (a, b) => a,
    k_max: (a, b) => b,
    mean: (a, b) => (a + b) / 2,
    gaussian: (a, b) => a * b,
    curvedness: (a, b) => Math.sqrt((a * a + b * b) / 2),
    shape_index: (a, b) => (a * a + b * b > 0 ? (2 / Math.PI) * Math.atan2(a + b, b - a) : NaN),
  };

  function fieldValues(name, kMin, kMax) {
    const formula = FIELD_FORMULAS[name], n = kMin.length, out = new Float32Array(n);
    for (let i = 0; i < n; i++) out[i] = formula(kMin[i], kMax[i]);
    return out;
  }

  // ---- colour maps (interpolated between anchors, 256 entries) ------------------------------------

  const ANCHORS = {
    // blue - white - red, for signed fields (ColorBrewer RdBu anchors, reversed)
    diverging: ["#053061", "#2166ac", "#4393c3", "#92c5de", "#f7f7f7", "#f4a582", "#d6604d", "#b2182b", "#67001f"],
    // viridis anchors, for fields >= 0
    sequential: ["#440154", "#482878", "#3e4989", "#31688e", "#26828e", "#1f9e89", "#35b779", "#6ece58",
                 "#b5de2b", "#fde725"],
  };
  const INVALID_GREY = [150, 150, 150];

  function colourTable(name) {
    const anchors = ANCHORS[name].map((hex) => [1, 3, 5].map((k) => parseInt(hex.slice(k, k + 2), 16)));
    const table = new Uint8Array(256 * 4);
    for (let i = 0; i < 256; i++) {
      const x = (i / 255) * (anchors.length - 1);
      const k = Math.min(Math.floor(x), anchors.length - 2);
      const t = x - k;
      for (let c = 0; c < 3; c++) table[4 * i + c] = Math.round(anchors[k][c] * (1 - t) + anchors[k + 1][c] * t);
      table[4 * i + 3] = 255;
    }
    return table;
  }

  // ---- small matrix algebra (column-major 4x4, as WebGL takes them) -------------------------------

  function multiply(a, b) {
    const out = new Float32Array(16);
    for (let col = 0; col < 4; col++) {
      for (let row = 0; row < 4; row++) {
        let s = 0;
        for (let k = 0; k < 4; k++) s += a[k * 4 + row] * b[col * 4 + k];
        out[col * 4 + row] = s;
      }
    }
    return out;
  }

  function perspective(fovy, aspect, near, far) {
    const f = 1 / Math.tan(fovy / 2);
    const out = new Float32Array(16);
    out[0] = f / aspect; out[5] = f;
    out[10] = (far + near) / (near - far); out[11] = -1;
    out[14] = (2 * far * near) / (near - far);
    return out;
  }

  // rotation as a 3x3 row-major array: rows are the screen axes (right, up, towards the viewer) in mesh coordinates
  function rotationAbout(axis, angle) {
    const [x, y, z] = axis, c = Math.cos(angle), s = Math.sin(angle), t = 1 - c;
    return [t * x * x + c, t * x * y - s * z, t * x * z + s * y,
            t * x * y + s * z, t * y * y + c, t * y * z - s * x,
            t * x * z - s * y, t * y * z + s * x, t * z * z + c];
  }

  function multiply3(a, b) {
    const out = new Array(9).fill(0);
    for (let i = 0; i < 3; i++) for (let j = 0; j < 3; j++) for (let k = 0; k < 3; k++) out[3 * i + j] += a[3 * i + k] * b[3 * k + j];
    return out;
  }

  function orthonormalize(r) {  // Gram-Schmidt on the rows, against drift after many small rotations
    const rows = [r.slice(0, 3), r.slice(3, 6)];
    const norm = (v) => { const l = Math.hypot(...v); return v.map((x) => x / l); };
    const a = norm(rows[0]);
    const d = a[0] * rows[1][0] + a[1] * rows[1][1] + a[2] * rows[1][2];
    const b = norm(rows[1].map((x, k) => x - d * a[k]));
    const c = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    return [...a, ...b, ...c];
  }

  const UP_ROTATIONS = {  // rows: screen right, screen up, towards the viewer
    y: [1, 0, 0, 0, 1, 0, 0, 0, 1],
    z: [1, 0, 0, 0, 0, 1, 0, -1, 0],
    x: [0, -1, 0, 1, 0, 0, 0, 0, 1],
  };

  // ---- WebGL --------------------------------------------------------------------------------------

  const SHADERS = {
    surfaceVertex: `#version 300 es
      uniform mat4 u_matrix;
      uniform mat3 u_rotation;
      uniform float u_point_scale;
      in vec3 a_position;
      in vec3 a_normal;
      in float a_value;
      in float a_invalid;
      out vec3 v_normal;
      out float v_value;
      out float v_invalid;
      void main() {
        gl_Position = u_matrix * vec4(a_position, 1.0);
        v_normal = u_rotation * a_normal;
        v_value = a_value;
        v_invalid = a_invalid;
        gl_PointSize = clamp(u_point_scale / gl_Position.w, 2.0, 64.0);
      }`,
    surfaceFragment: `#version 300 es
      precision highp float;
      uniform sampler2D u_colours;
      uniform vec2 u_limits;
      uniform vec3 u_invalid_colour;
      uniform bool u_points;
      in vec3 v_normal;
      in float v_value;
      in float v_invalid;
      out vec4 colour;
      void main() {
        if (u_points && length(gl_PointCoord - 0.5) > 0.5) discard;
        vec3 base;
        if (v_invalid > 0.5) {
          base = u_invalid_colour;
        } else {
          float t = clamp((v_value - u_limits.x) / (u_limits.y - u_limits.x), 0.0, 1.0);
          base = texture(u_colours, vec2(t * (255.0 / 256.0) + 0.5 / 256.0, 0.5)).rgb;
        }
        float light = 1.0;
        if (length(v_normal) > 0.1) light = 0.3 + 0.7 * abs(normalize(v_normal).z);
        colour = vec4(base * light, 1.0);
      }`,
    pickVertex: `#version 300 es
      uniform mat4 u_matrix;
      uniform float u_point_scale;
      in vec3 a_position;
      flat out uint v_id;
      out vec3 v_position;
      void main() {
        gl_Position = u_matrix * vec4(a_position, 1.0);
        v_id = uint(gl_VertexID);
        v_position = a_position;
        gl_PointSize = clamp(u_point_scale / gl_Position.w, 2.0, 64.0);
      }`,
    pickFragment: `#version 300 es
      precision highp float;
      flat in uint v_id;
      in vec3 v_position;
      out uvec4 picked;
      void main() {
        picked = uvec4(v_id + 1u, floatBitsToUint(v_position.x), floatBitsToUint(v_position.y),
                       floatBitsToUint(v_position.z));
      }`,
    lineVertex: `#version 300 es
      uniform mat4 u_matrix;
      in vec3 a_position;
      void main() { gl_Position = u_matrix * vec4(a_position, 1.0); }`,
    lineFragment: `#version 300 es
      precision highp float;
      uniform vec3 u_colour;
      out vec4 colour;
      void main() { colour = vec4(u_colour, 1.0); }`,
  };

  function compile(gl, vertexSource, fragmentSource) {
    const program = gl.createProgram();
    for (const [type, source] of [[gl.VERTEX_SHADER, vertexSource], [gl.FRAGMENT_SHADER, fragmentSource]]) {
      const shader = gl.createShader(type);
      gl.shaderSource(shader, source);
      gl.compileShader(shader);
      if (!gl.getShaderParameter(shader, gl.COMPILE_STATUS)) throw new Error("shader: " + gl.getShaderInfoLog(shader));
      gl.attachShader(program, shader);
    }
    gl.linkProgram(program);
    if (!gl.getProgramParameter(program, gl.LINK_STATUS)) throw new Error("program: " + gl.getProgramInfoLog(program));
    const uniforms = {};
    const count = gl.getProgramParameter(program, gl.ACTIVE_UNIFORMS);
    for (let i = 0; i < count; i++) {
      const name = gl.getActiveUniform(program, i).name;
      uniforms[name] = gl.getUniformLocation(program, name);
    }
    return { program, uniforms };
  }

  function buffer(gl, target, data, usage) {
    const b = gl.createBuffer();
    gl.bindBuffer(target, b);
    gl.bufferData(target, data, usage || gl.STATIC_DRAW);
    return b;
  }

  // ---- the viewer ----------------------------------------------------------------------------------

  function hashState() {
    const state = {};
    for (const part of window.location.hash.replace(/^#/, "").split("&")) {
      if (!part) continue;
      const [key, value] = part.split("=");
      state[decodeURIComponent(key)] = decodeURIComponent(value || "");
    }
    return state;
  }

  function formatNumber(x) {
    if (!Number.isFinite(x)) return String(x);
    if (x === 0) return "0";
    return String(parseFloat(x.toPrecision(3)));
  }

  async function main() {
    if (!littleEndian()) throw new Error("this viewer needs a little-endian machine");
    const meta = JSON.parse(document.getElementById("meshcurv-meta").textContent);
    const data = {};
    for (const [name, spec] of Object.entries(meta.arrays)) data[name] = await readArray(spec);
    // the scales (one unless the page holds the results of several radii): their arrays are swapped into `data`
    const scales = meta.scales ||
      [{ label: "", fields: meta.fields, stroke_half_length: meta.stroke_half_length, details: meta.details }];
    const SCALED = ["k_min", "k_max", "invalid_reason", "direction_vertices", "dir_min", "dir_max"];
    const scaleArrays = scales.map((_, s) => Object.fromEntries(SCALED.map((name) => [name, data[s ? `${name}_s${s}` : name]])));
    const decodedAt = performance.now();
    const nVertices = meta.n_vertices;
    const isMesh = meta.kind === "mesh";

    const canvas = document.getElementById("view");
    // multisampling costs a renderer without a GPU (SwiftShader) seconds a frame on a million triangles
    const antialias = !(isMesh && meta.n_faces > 500000);
    const gl = canvas.getContext("webgl2", { antialias, preserveDrawingBuffer: true });
    if (!gl) throw new Error("this browser has no WebGL2 (needed to draw the mesh)");

    const surface = compile(gl, SHADERS.surfaceVertex, SHADERS.surfaceFragment);
    const pick = compile(gl, SHADERS.pickVertex, SHADERS.pickFragment);
    const line = compile(gl, SHADERS.lineVertex, SHADERS.lineFragment);

    // normals: from the faces (area weighted) for meshes, from the estimate for point clouds
    let normals;
    if (isMesh) {
      const p = data.positions, f = data.faces;
      normals = new Float32Array(3 * nVertices);
      for (let t = 0; t < f.length; t += 3) {
        const a = 3 * f[t], b = 3 * f[t + 1], c = 3 * f[t + 2];
        const ux = p[b] - p[a], uy = p[b + 1] - p[a + 1], uz = p[b + 2] - p[a + 2];
        const vx = p[c] - p[a], vy = p[c + 1] - p[a + 1], vz = p[c + 2] - p[a + 2];
        const nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
        normals[a] += nx; normals[a + 1] += ny; normals[a + 2] += nz;
        normals[b] += nx; normals[b + 1] += ny; normals[b + 2] += nz;
        normals[c] += nx; normals[c + 1] += ny; normals[c + 2] += nz;
      }
      for (let v = 0; v < normals.length; v += 3) {
        const l = Math.hypot(normals[v], normals[v + 1], normals[v + 2]);
        if (l > 0) { normals[v] /= l; normals[v + 1] /= l; normals[v + 2] /= l; }
      }
    } else {
      normals = new Float32Array(data.normals.length);
      for (let i = 0; i < normals.length; i++) normals[i] = data.normals[i] / 127;
    }

    const normalsAt = performance.now();
    // vertex arrays: surface (position, normal, value, invalid) and pick (position)
    const positionBuffer = buffer(gl, gl.ARRAY_BUFFER, data.positions);
    const normalBuffer = buffer(gl, gl.ARRAY_BUFFER, normals);
    const valueBuffer = buffer(gl, gl.ARRAY_BUFFER, new Float32Array(nVertices), gl.DYNAMIC_DRAW);
    const invalidBuffer = buffer(gl, gl.ARRAY_BUFFER, new Uint8Array(nVertices), gl.DYNAMIC_DRAW);
    const indexBuffer = isMesh ? buffer(gl, gl.ELEMENT_ARRAY_BUFFER, data.faces) : null;

    function attribute(program, name, glBuffer, size, type, normalized) {
      const location = gl.getAttribLocation(program, name);
      if (location < 0) return;
      gl.bindBuffer(gl.ARRAY_BUFFER, glBuffer);
      gl.enableVertexAttribArray(location);
      gl.vertexAttribPointer(location, size, type, normalized, 0, 0);
    }

    function surfaceVertexArray(indices) {  // the surface's attributes, drawn with these indices (or none)
      const vao = gl.createVertexArray();
      gl.bindVertexArray(vao);
      attribute(surface.program, "a_position", positionBuffer, 3, gl.FLOAT, false);
      attribute(surface.program, "a_normal", normalBuffer, 3, gl.FLOAT, false);
      attribute(surface.program, "a_value", valueBuffer, 1, gl.FLOAT, false);
      attribute(surface.program, "a_invalid", invalidBuffer, 1, gl.UNSIGNED_BYTE, true);
      if (indices) gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, indices);
      gl.bindVertexArray(null);
      return vao;
    }

    const surfaceArray = surfaceVertexArray(indexBuffer);
    const pickArray = gl.createVertexArray();
    gl.bindVertexArray(pickArray);
    attribute(pick.program, "a_position", positionBuffer, 3, gl.FLOAT, false);
    if (indexBuffer) gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, indexBuffer);
    gl.bindVertexArray(null);

    // a preview for slow renderers: while the mouse drags, every step-th vertex is drawn as a point
    const previewStep = Math.max(1, Math.ceil(nVertices / 100000));
    let preview = null;
    if (isMesh && previewStep > 1) {
      const ids = new Uint32Array(Math.ceil(nVertices / previewStep));
      for (let i = 0; i < ids.length; i++) ids[i] = i * previewStep;
      const vao = surfaceVertexArray(buffer(gl, gl.ELEMENT_ARRAY_BUFFER, ids));
      preview = { vao, count: ids.length, spacing: meta.point_spacing * Math.sqrt(previewStep) };
    }
    let slowFrames = false;  // set when the first full frame took more than 100 ms

    const colourTextures = {};
    for (const name of Object.keys(ANCHORS)) {
      const texture = gl.createTexture();
      gl.bindTexture(gl.TEXTURE_2D, texture);
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA, 256, 1, 0, gl.RGBA, gl.UNSIGNED_BYTE, colourTable(name));
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
      colourTextures[name] = texture;
    }

    // the pick target: one pixel of (vertex id + 1, x, y, z) and a depth buffer
    const pickTexture = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, pickTexture);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32UI, 1, 1, 0, gl.RGBA_INTEGER, gl.UNSIGNED_INT, null);
    const pickDepth = gl.createRenderbuffer();
    gl.bindRenderbuffer(gl.RENDERBUFFER, pickDepth);
    gl.renderbufferStorage(gl.RENDERBUFFER, gl.DEPTH_COMPONENT24, 1, 1);
    const pickFramebuffer = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, pickFramebuffer);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, pickTexture, 0);
    gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.DEPTH_ATTACHMENT, gl.RENDERBUFFER, pickDepth);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);

    // principal direction strokes, centred on a subsample of the vertices, lifted off the surface a little
    let strokes = {};
    function buildStrokes(h) {
      for (const stroke of Object.values(strokes)) { gl.deleteBuffer(stroke.buffer); gl.deleteVertexArray(stroke.vao); }
      strokes = {};
      if (!data.direction_vertices) return;
      const lift = 0.1 * h, ids = data.direction_vertices, p = data.positions;
      for (const name of ["dir_max", "dir_min"]) {
        const d = data[name], out = new Float32Array(ids.length * 6);
        for (let i = 0; i < ids.length; i++) {
          const v = ids[i];
          for (let c = 0; c < 3; c++) {
            const centre = p[3 * v + c] + lift * normals[3 * v + c];
            out[6 * i + c] = centre - h * d[3 * i + c];
            out[6 * i + 3 + c] = centre + h * d[3 * i + c];
          }
        }
        const vao = gl.createVertexArray(), strokeBuffer = buffer(gl, gl.ARRAY_BUFFER, out);
        gl.bindVertexArray(vao);
        attribute(line.program, "a_position", strokeBuffer, 3, gl.FLOAT, false);
        gl.bindVertexArray(null);
        strokes[name] = { vao, buffer: strokeBuffer, count: 2 * ids.length };
      }
    }

    // ---- state and controls ----
    const hash = hashState();
    const fovy = Math.PI / 6;
    const panel = document.getElementById("panel");

    // the width of the canvas left of the panel, in CSS pixels, when the window is wide enough to keep it free
    function panelShift() {
      const width = canvas.clientWidth, taken = panel.offsetLeft + panel.offsetWidth;
      return width > 1.8 * taken ? taken : 0;
    }

    function fitDistance() {  // the bounding sphere fills the free part of the window
      const free = Math.max(1, canvas.clientWidth - panelShift()), height = Math.max(1, canvas.clientHeight);
      const half = Math.min(fovy / 2, Math.atan(Math.tan(fovy / 2) * free / height));
      return (meta.radius / Math.sin(half)) * 1.1;
    }

    const controls = {
      field: document.getElementById("field"),
      low: document.getElementById("low"),
      high: document.getElementById("high"),
      auto: document.getElementById("auto"),
      directions: document.getElementById("directions"),
      scale: document.getElementById("scale"),
      probe: document.getElementById("probe"),
      bar: document.getElementById("bar"),
      barLow: document.getElementById("bar-low"),
      barMiddle: document.getElementById("bar-middle"),
      barHigh: document.getElementById("bar-high"),
      barLabel: document.getElementById("bar-label"),
    };
    document.getElementById("title").textContent = meta.title;
    pageTitle = meta.title;
    document.getElementById("subtitle").textContent = meta.subtitle;
    document.getElementById("subtitle").title = meta.details;
    for (const name of Object.keys(meta.fields)) {
      const option = document.createElement("option");
      option.value = name;
      option.textContent = name;
      controls.field.appendChild(option);
    }
    scales.forEach((scale, index) => {
      const option = document.createElement("option");
      option.value = String(index);
      option.textContent = scale.label;
      controls.scale.appendChild(option);
    });
    document.getElementById("scale-choice").hidden = scales.length < 2;
    const hashScale = Number(hash.scale);
    const firstScale = Number.isInteger(hashScale) && hashScale >= 0 && hashScale < scales.length ? hashScale : 0;

    const state = {
      field: meta.fields[hash.field] ? hash.field : meta.field,
      scale: firstScale,
      limits: null,
      directions: scaleArrays[firstScale].direction_vertices && ["max", "min", "both"].includes(hash.directions)
        ? hash.directions : "none",
      target: [0, 0, 0],
      distance: fitDistance(),
      rotation: UP_ROTATIONS[meta.up],
    };
    const elevation = Number(hash.elevation ?? meta.elevation) * Math.PI / 180;
    const azimuth = Number(hash.azimuth ?? meta.azimuth) * Math.PI / 180;
    state.rotation = multiply3(rotationAbout([1, 0, 0], elevation), multiply3(rotationAbout([0, 1, 0], azimuth), state.rotation));
    const homeView = { target: state.target.slice(), distance: state.distance, rotation: state.rotation.slice() };

    // a scale: its arrays into `data`, its fields' limits into `meta.fields`, its strokes; the limits stay
    function useScale(index) {
      state.scale = index;
      Object.assign(data, scaleArrays[index]);
      meta.fields = scales[index].fields;
      buildStrokes(scales[index].stroke_half_length);
      controls.scale.value = String(index);
      controls.directions.disabled = !data.direction_vertices;
      controls.directions.title = data.direction_vertices ? "" : "this method gives no principal directions";
      if (!data.direction_vertices) { state.directions = "none"; controls.directions.value = "none"; }
      document.getElementById("subtitle").title = scales[index].details;
    }

    function setScale(index) {
      useScale(index);
      setField(state.field, state.limits);
    }

    let values = null;
    function setField(name, limits) {
      state.field = name;
      values = fieldValues(name, data.k_min, data.k_max);
      const invalid = new Uint8Array(nVertices);
      const shown = new Float32Array(nVertices);
      let nInvalid = 0;
      for (let i = 0; i < nVertices; i++) {
        if (data.invalid_reason[i] !== 0 || !Number.isFinite(values[i])) { invalid[i] = 255; nInvalid++; }
        else shown[i] = values[i];
      }
      gl.bindBuffer(gl.ARRAY_BUFFER, valueBuffer);
      gl.bufferSubData(gl.ARRAY_BUFFER, 0, shown);
      gl.bindBuffer(gl.ARRAY_BUFFER, invalidBuffer);
      gl.bufferSubData(gl.ARRAY_BUFFER, 0, invalid);
      state.nInvalid = nInvalid;
      controls.field.value = name;
      if (!(limits && setLimits(limits))) setLimits(meta.fields[name].limits);
    }

    function setLimits(limits) {
      const [low, high] = limits.map(Number);
      const ok = Number.isFinite(low) && Number.isFinite(high) && low < high;
      controls.low.classList.toggle("bad", !ok);
      controls.high.classList.toggle("bad", !ok);
      if (!ok) return false;
      state.limits = [low, high];
      controls.low.value = formatNumber(low);
      controls.high.value = formatNumber(high);
      drawColourBar();
      requestDraw();
      return true;
    }

    function drawColourBar() {
      const spec = meta.fields[state.field];
      const context = controls.bar.getContext("2d");
      const table = colourTable(spec.signed ? "diverging" : "sequential");
      const image = context.createImageData(256, 1);
      image.data.set(table);
      const scratch = document.createElement("canvas");
      scratch.width = 256; scratch.height = 1;
      scratch.getContext("2d").putImageData(image, 0, 0);
      context.imageSmoothingEnabled = false;
      context.drawImage(scratch, 0, 0, controls.bar.width, controls.bar.height);
      const [low, high] = state.limits;
      controls.barLow.textContent = "≤ " + formatNumber(low);
      controls.barHigh.textContent = "≥ " + formatNumber(high);
      controls.barMiddle.textContent = formatNumber((low + high) / 2);
      controls.barLabel.textContent = `${state.field}: ${spec.label} [${spec.unit}]` +
        (state.nInvalid ? `; grey: ${state.nInvalid} vertices without a value` : "");
    }

    // ---- drawing ----

    function matrices(width, height) {
      const r = state.rotation, t = state.target, d = state.distance;
      const view = new Float32Array(16);  // column-major: rotation rows become the matrix rows
      for (let i = 0; i < 3; i++) {
        for (let j = 0; j < 3; j++) view[j * 4 + i] = r[3 * i + j];
        view[12 + i] = -(r[3 * i] * t[0] + r[3 * i + 1] * t[1] + r[3 * i + 2] * t[2]);
      }
      view[14] -= d;
      view[15] = 1;
      // near and far around the bounding sphere (centred on 0), wherever panning took the camera
      const centre = Math.hypot(view[12], view[13], view[14]);
      const near = Math.max(centre - 1.05 * meta.radius, centre * 1e-3, 1e-6 * meta.radius);
      const far = Math.max(centre + 1.05 * meta.radius, 2 * near);
      const projection = perspective(fovy, width / height, near, far);
      projection[8] = -(panelShift() / canvas.clientWidth);  // the picture moves right, beside the panel
      const rotation = new Float32Array([r[0], r[3], r[6], r[1], r[4], r[7], r[2], r[5], r[8]]);
      return { matrix: multiply(projection, view), rotation };
    }

    function pointScale(height, spacing) {
      return spacing ? 1.5 * spacing * height / (2 * Math.tan(fovy / 2)) : 0;
    }

    function resize() {
      const ratio = window.devicePixelRatio || 1;
      const width = Math.max(1, Math.round(canvas.clientWidth * ratio));
      const height = Math.max(1, Math.round(canvas.clientHeight * ratio));
      if (canvas.width !== width || canvas.height !== height) { canvas.width = width; canvas.height = height; }
    }

    function draw(quick) {
      resize();
      const points = !isMesh || (quick && preview);
      const { matrix, rotation } = matrices(canvas.width, canvas.height);
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      gl.viewport(0, 0, canvas.width, canvas.height);
      gl.clearColor(1, 1, 1, 1);
      gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
      gl.enable(gl.DEPTH_TEST);
      gl.enable(gl.POLYGON_OFFSET_FILL);
      gl.polygonOffset(1, 1);
      gl.useProgram(surface.program);
      gl.uniformMatrix4fv(surface.uniforms.u_matrix, false, matrix);
      gl.uniformMatrix3fv(surface.uniforms.u_rotation, false, rotation);
      gl.uniform1f(surface.uniforms.u_point_scale,
                   pointScale(canvas.height, isMesh ? (points ? preview.spacing : 0) : meta.point_spacing));
      gl.uniform2f(surface.uniforms.u_limits, state.limits[0], state.limits[1]);
      gl.uniform3f(surface.uniforms.u_invalid_colour, ...INVALID_GREY.map((c) => c / 255));
      gl.uniform1i(surface.uniforms.u_points, points ? 1 : 0);
      gl.activeTexture(gl.TEXTURE0);
      gl.bindTexture(gl.TEXTURE_2D, colourTextures[meta.fields[state.field].signed ? "diverging" : "sequential"]);
      gl.uniform1i(surface.uniforms.u_colours, 0);
      if (isMesh && points) {
        gl.bindVertexArray(preview.vao);
        gl.drawElements(gl.POINTS, preview.count, gl.UNSIGNED_INT, 0);
      } else {
        gl.bindVertexArray(surfaceArray);
        if (isMesh) gl.drawElements(gl.TRIANGLES, data.faces.length, gl.UNSIGNED_INT, 0);
        else gl.drawArrays(gl.POINTS, 0, nVertices);
      }
      gl.disable(gl.POLYGON_OFFSET_FILL);
      const shown = { max: ["dir_max"], min: ["dir_min"], both: ["dir_max", "dir_min"], none: [] }[state.directions];
      if (shown.length) {
        gl.useProgram(line.program);
        gl.uniformMatrix4fv(line.uniforms.u_matrix, false, matrix);
        for (const name of shown) {
          gl.uniform3fv(line.uniforms.u_colour, name === "dir_max" ? [0, 0, 0] : [0.45, 0.45, 0.45]);
          gl.bindVertexArray(strokes[name].vao);
          gl.drawArrays(gl.LINES, 0, strokes[name].count);
        }
      }
      gl.bindVertexArray(null);
    }

    let drawPending = false, settleTimer = null;
    function requestDraw(moving) {
      if (!state.limits) return;
      const quick = Boolean(moving && slowFrames && preview);
      if (quick) {  // the full frame once the motion stops
        clearTimeout(settleTimer);
        settleTimer = setTimeout(() => requestDraw(false), 250);
      }
      if (drawPending) return;
      drawPending = true;
      requestAnimationFrame(() => { drawPending = false; draw(quick); });
    }

    // ---- picking: the vertex under a pixel (CSS pixels from the top left) ----
    let incident = null;  // vertex -> faces (CSR), built on the first pick of a mesh

    function incidentFaces() {
      const f = data.faces, start = new Uint32Array(nVertices + 1);
      for (let i = 0; i < f.length; i++) start[f[i] + 1]++;
      for (let v = 0; v < nVertices; v++) start[v + 1] += start[v];
      const fill = start.slice(0, nVertices), list = new Uint32Array(f.length);
      for (let i = 0; i < f.length; i++) list[fill[f[i]]++] = (i / 3) | 0;
      return { start, list };
    }

    function pickAt(x, y) {
      resize();
      const ratio = canvas.width / canvas.clientWidth;
      const px = x * ratio, py = canvas.height - y * ratio;  // GL pixels, origin bottom left
      const { matrix } = matrices(canvas.width, canvas.height);
      // a projection that maps the picked pixel onto the whole 1x1 target
      const cx = (2 * px) / canvas.width - 1, cy = (2 * py) / canvas.height - 1;
      const zoom = new Float32Array(16);
      zoom[0] = canvas.width; zoom[5] = canvas.height; zoom[10] = 1; zoom[15] = 1;
      zoom[12] = -canvas.width * cx; zoom[13] = -canvas.height * cy;
      gl.bindFramebuffer(gl.FRAMEBUFFER, pickFramebuffer);
      gl.viewport(0, 0, 1, 1);
      gl.clearBufferuiv(gl.COLOR, 0, new Uint32Array([0, 0, 0, 0]));
      gl.clearBufferfv(gl.DEPTH, 0, new Float32Array([1]));
      gl.enable(gl.DEPTH_TEST);
      gl.useProgram(pick.program);
      gl.uniformMatrix4fv(pick.uniforms.u_matrix, false, multiply(zoom, matrix));
      gl.uniform1f(pick.uniforms.u_point_scale, pointScale(canvas.height, isMesh ? 0 : meta.point_spacing));
      gl.bindVertexArray(pickArray);
      if (isMesh) gl.drawElements(gl.TRIANGLES, data.faces.length, gl.UNSIGNED_INT, 0);
      else gl.drawArrays(gl.POINTS, 0, nVertices);
      gl.bindVertexArray(null);
      const pixel = new Uint32Array(4);
      gl.readPixels(0, 0, 1, 1, gl.RGBA_INTEGER, gl.UNSIGNED_INT, pixel);
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      if (pixel[0] === 0) return null;
      let vertex = pixel[0] - 1;
      if (isMesh) {  // the nearest corner of the faces around the drawn vertex to the surface point hit
        const point = new Float32Array(new Uint32Array([pixel[1], pixel[2], pixel[3]]).buffer);
        incident = incident || incidentFaces();
        const p = data.positions, f = data.faces;
        let best = Infinity;
        for (let k = incident.start[vertex]; k < incident.start[vertex + 1]; k++) {
          for (let c = 0; c < 3; c++) {
            const v = f[3 * incident.list[k] + c];
            const d = (p[3 * v] - point[0]) ** 2 + (p[3 * v + 1] - point[1]) ** 2 + (p[3 * v + 2] - point[2]) ** 2;
            if (d < best) { best = d; vertex = v; }
          }
        }
      }
      return vertex;
    }

    function describe(vertex) {
      if (vertex === null) return { text: "", data: { probeVertex: "none" } };
      const reason = data.invalid_reason[vertex];
      const value = values[vertex];
      const spec = meta.fields[state.field];
      let text = `vertex ${vertex}${scales.length > 1 ? ` (${scales[state.scale].label})` : ""}: `;
      if (reason !== 0) text += `no value (${meta.invalid_reasons[reason] || "invalid"})`;
      else if (!Number.isFinite(value)) text += `${state.field} undefined here`;
      else text += `${state.field} = ${value.toPrecision(4)} ${spec.unit}; k_min = ${data.k_min[vertex].toPrecision(4)}, ` +
        `k_max = ${data.k_max[vertex].toPrecision(4)}`;
      return {
        text,
        data: { probeVertex: vertex, probeField: state.field, probeScale: state.scale, probeValue: reason === 0 ? value : "NaN" },
      };
    }

    // ---- mouse: left drag rotates, right or shift drag pans, wheel zooms, double click resets ----
    let drag = null, hoverTimer = null;
    canvas.addEventListener("contextmenu", (event) => event.preventDefault());
    canvas.addEventListener("pointerdown", (event) => {
      canvas.setPointerCapture(event.pointerId);
      drag = { x: event.clientX, y: event.clientY, pan: event.button === 2 || event.shiftKey };
    });
    canvas.addEventListener("pointerup", () => { drag = null; requestDraw(false); });
    canvas.addEventListener("pointermove", (event) => {
      if (!drag) {
        clearTimeout(hoverTimer);
        // a pick draws the whole mesh once more: wait for the mouse to rest longer where frames are slow
        hoverTimer = setTimeout(() => { controls.probe.textContent = describe(pickAt(event.offsetX, event.offsetY)).text; },
                                slowFrames ? 400 : 60);
        return;
      }
      const dx = event.clientX - drag.x, dy = event.clientY - drag.y;
      drag.x = event.clientX; drag.y = event.clientY;
      if (drag.pan) {
        const scale = (2 * state.distance * Math.tan(fovy / 2)) / canvas.clientHeight, r = state.rotation;
        for (let c = 0; c < 3; c++) state.target[c] -= scale * (dx * r[c] - dy * r[3 + c]);
      } else {
        const length = Math.hypot(dx, dy);
        if (length === 0) return;
        const angle = (length / Math.min(canvas.clientWidth, canvas.clientHeight)) * Math.PI;
        state.rotation = orthonormalize(multiply3(rotationAbout([dy / length, dx / length, 0], angle), state.rotation));
      }
      requestDraw(true);
    });
    canvas.addEventListener("wheel", (event) => {
      event.preventDefault();
      state.distance *= Math.exp(Math.max(-0.5, Math.min(0.5, event.deltaY * 0.001)));
      requestDraw(true);
    }, { passive: false });
    canvas.addEventListener("dblclick", () => {
      Object.assign(state, { target: homeView.target.slice(), distance: homeView.distance, rotation: homeView.rotation.slice() });
      requestDraw();
    });
    window.addEventListener("resize", requestDraw);
    // the choices go into the address (#field=...&lo=...), so that a copied address shows the same
    function keepInAddress() {
      const hashed = `#field=${state.field}&lo=${state.limits[0]}&hi=${state.limits[1]}&directions=${state.directions}` +
        (scales.length > 1 ? `&scale=${state.scale}` : "");
      history.replaceState(null, "", hashed);
    }
    controls.field.addEventListener("change", () => { setField(controls.field.value); keepInAddress(); });
    controls.scale.addEventListener("change", () => { setScale(Number(controls.scale.value)); keepInAddress(); });
    controls.low.addEventListener("change", () => { setLimits([controls.low.value, state.limits[1]]); keepInAddress(); });
    controls.high.addEventListener("change", () => { setLimits([state.limits[0], controls.high.value]); keepInAddress(); });
    controls.auto.addEventListener("click", () => { setLimits(meta.fields[state.field].limits); keepInAddress(); });
    controls.directions.value = state.directions;
    controls.directions.addEventListener("change", () => {
      state.directions = controls.directions.value;
      keepInAddress();
      requestDraw();
    });

    // ---- first frame, drawn now (not on an animation frame) so that it is there when the page has loaded ----
    const hashLimits = "lo" in hash && "hi" in hash ? [hash.lo, hash.hi] : null;
    useScale(state.scale);
    controls.directions.value = state.directions;
    setField(state.field, hashLimits);
    // the panel has its contents now: fit the mesh beside it
    state.distance = fitDistance() / (hash.zoom && Number(hash.zoom) > 0 ? Number(hash.zoom) : 1);
    homeView.distance = state.distance;
    const uploadedAt = performance.now();
    drawPending = false;
    draw();
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));  // waits for the frame
    const drawnAt = performance.now();
    slowFrames = drawnAt - uploadedAt > 100;
    const facts = {
      openMs: Math.round(drawnAt), scriptStartMs: Math.round(startedAt), decodeMs: Math.round(decodedAt - startedAt),
      normalsMs: Math.round(normalsAt - decodedAt), uploadMs: Math.round(uploadedAt - normalsAt),
      drawMs: Math.round(drawnAt - uploadedAt),
      field: state.field, scale: state.scale, scales: scales.length,
      low: state.limits[0], high: state.limits[1], directions: state.directions,
      vertices: nVertices, renderer: rendererName(gl),
    };
    let text = `${nVertices} ${isMesh ? "vertices" : "points"}, first frame at ${facts.openMs} ms`;
    if (hash.probe) {
      const [x, y] = hash.probe.split(",").map(Number);
      const probed = describe(pickAt(x, y));
      controls.probe.textContent = probed.text || "nothing at the probe";
      Object.assign(facts, probed.data);
    }
    report("ok", text, facts);

    // for scripts and tests: the state, and frames drawn on demand
    window.meshcurvViewer = {
      state, pickAt, describe, setField, setLimits, setScale,
      setDirections(value) { state.directions = value; controls.directions.value = value; draw(); },
      rotate(dx, dy) {
        const length = Math.hypot(dx, dy);
        state.rotation = orthonormalize(multiply3(rotationAbout([dy / length, dx / length, 0], length), state.rotation));
      },
      timeFrames(count, quick) {  // milliseconds per frame, each turned a little and finished
        const start = performance.now();
        for (let i = 0; i < count; i++) {
          this.rotate(0.05, 0);
          draw(quick);
          gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
        }
        return (performance.now() - start) / count;
      },
    };
  }

  main().catch(fail);
})();
