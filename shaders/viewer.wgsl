// The viewer: coloured triangles (the figure, its shadows) and lines (grid, root path) in
// world space (metres, Y up), projected by one view-projection matrix. Triangles with a
// normal are lit by one directional light, the sky and an ambient term (the numbers come from
// web/src/viewer/scene.rs, which shades the 2D renderer's triangles the same way); a zero
// normal (lines, shadows, the skeleton's ribbons) means unlit. Colours arrive in sRGB: on a
// non-sRGB canvas they are written as they are, on an sRGB one (some WebGL2 canvases)
// decoded first, so both show the same colours.

struct Camera {
    view_projection: mat4x4<f32>,
    // xyz: unit direction towards the light.
    light: vec4<f32>,
    // x: 1 when the canvas is an sRGB format; y: ambient; z: sky; w: diffuse.
    params: vec4<f32>,
};

@group(0) @binding(0) var<uniform> camera: Camera;

struct VertexOut {
    @builtin(position) position: vec4<f32>,
    @location(0) normal: vec3<f32>,
    @location(1) color: vec4<f32>,
};

@vertex
fn vs_main(
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) color: vec4<f32>,
) -> VertexOut {
    var out: VertexOut;
    out.position = camera.view_projection * vec4<f32>(position, 1.0);
    out.normal = normal;
    out.color = color;
    return out;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    var rgb = in.color.rgb;
    if (dot(in.normal, in.normal) > 1e-8) {
        let n = normalize(in.normal);
        let k = camera.params.y + camera.params.z * (0.5 + 0.5 * n.y)
            + camera.params.w * max(dot(n, camera.light.xyz), 0.0);
        rgb = min(rgb * k, vec3<f32>(1.0));
    }
    if (camera.params.x > 0.5) {
        rgb = pow(rgb, vec3<f32>(2.2));
    }
    return vec4<f32>(rgb, in.color.a);
}
