//! The renderer's GLSL programs (a shaded mesh, flat clip-space primitives),
//! compiling and linking them, and GL error checks.

use glow::HasContext;

use crate::error::{Error, Result};

pub(super) const MESH_VS: &str = r"#version 330 core
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_color;
uniform mat4 u_view_proj;
out vec3 v_pos;
out vec3 v_normal;
out vec3 v_color;
void main() {
    v_pos = a_pos;
    v_normal = a_normal;
    v_color = a_color;
    gl_Position = u_view_proj * vec4(a_pos, 1.0);
}
";

pub(super) const MESH_FS: &str = r"#version 330 core
in vec3 v_pos;
in vec3 v_normal;
in vec3 v_color;
uniform vec3 u_eye;
uniform vec3 u_view_dir;    // eye towards target, unit
uniform int u_ortho;
uniform int u_headlight;
uniform vec3 u_light_dir;   // towards the light, unit
uniform float u_ambient;
uniform int u_vertex_color;
uniform vec3 u_color;
out vec4 o_color;
void main() {
    vec3 to_eye = u_ortho != 0 ? -u_view_dir : normalize(u_eye - v_pos);
    float len = length(v_normal);
    // A zero (or NaN) normal is shaded as if facing the eye rather than black.
    vec3 n = len > 0.0 ? v_normal / len : to_eye;
    // Two-sided: meshes with inconsistent orientation still shade correctly.
    if (dot(n, to_eye) < 0.0) n = -n;
    vec3 l = u_headlight != 0 ? to_eye : u_light_dir;
    float lambert = max(dot(n, l), 0.0);
    vec3 base = u_vertex_color != 0 ? v_color : u_color;
    o_color = vec4(base * (u_ambient + (1.0 - u_ambient) * lambert), 1.0);
}
";

pub(super) const CLIP_VS: &str = r"#version 330 core
layout(location = 0) in vec4 a_clip;
void main() { gl_Position = a_clip; }   // already projected: no transform (House & Li)
";

pub(super) const CLIP_FS: &str = r"#version 330 core
uniform vec4 u_color;
out vec4 o_color;
void main() { o_color = u_color; }
";

/// Uniform locations of the mesh program.
pub(super) struct MeshUniforms {
    pub(super) view_proj: Option<glow::NativeUniformLocation>,
    pub(super) eye: Option<glow::NativeUniformLocation>,
    pub(super) view_dir: Option<glow::NativeUniformLocation>,
    pub(super) ortho: Option<glow::NativeUniformLocation>,
    pub(super) headlight: Option<glow::NativeUniformLocation>,
    pub(super) light_dir: Option<glow::NativeUniformLocation>,
    pub(super) ambient: Option<glow::NativeUniformLocation>,
    pub(super) vertex_color: Option<glow::NativeUniformLocation>,
    pub(super) color: Option<glow::NativeUniformLocation>,
}

fn gl_error_name(e: u32) -> String {
    match e {
        glow::INVALID_ENUM => "GL_INVALID_ENUM".into(),
        glow::INVALID_VALUE => "GL_INVALID_VALUE".into(),
        glow::INVALID_OPERATION => "GL_INVALID_OPERATION".into(),
        glow::INVALID_FRAMEBUFFER_OPERATION => "GL_INVALID_FRAMEBUFFER_OPERATION".into(),
        glow::OUT_OF_MEMORY => "GL_OUT_OF_MEMORY".into(),
        other => format!("GL error 0x{other:04X}"),
    }
}

/// Returns the first pending GL error (and clears the rest) as an [`Error::Render`].
pub(super) fn check(gl: &glow::Context, what: &str) -> Result<()> {
    // SAFETY: glGetError only needs a current context, which every caller has made.
    let first = unsafe { gl.get_error() };
    if first == glow::NO_ERROR {
        return Ok(());
    }
    for _ in 0..16 {
        // SAFETY: as above.
        if unsafe { gl.get_error() } == glow::NO_ERROR {
            break;
        }
    }
    Err(Error::render(what, gl_error_name(first)))
}

/// Compiles and links a vertex + fragment program; the error carries the info log.
///
/// # Safety
/// The context of `gl` must be current.
pub(super) unsafe fn program(
    gl: &glow::Context,
    name: &str,
    vs: &str,
    fs: &str,
) -> Result<glow::NativeProgram> {
    unsafe {
        let prog = gl
            .create_program()
            .map_err(|e| Error::render(format!("glCreateProgram ({name})"), e))?;
        let mut shaders = Vec::new();
        for (kind, src, label) in [
            (glow::VERTEX_SHADER, vs, "vertex"),
            (glow::FRAGMENT_SHADER, fs, "fragment"),
        ] {
            let sh = gl
                .create_shader(kind)
                .map_err(|e| Error::render(format!("glCreateShader ({name} {label})"), e))?;
            gl.shader_source(sh, src);
            gl.compile_shader(sh);
            if !gl.get_shader_compile_status(sh) {
                return Err(Error::render(
                    format!("compiling the {name} {label} shader"),
                    gl.get_shader_info_log(sh),
                ));
            }
            gl.attach_shader(prog, sh);
            shaders.push(sh);
        }
        gl.link_program(prog);
        if !gl.get_program_link_status(prog) {
            return Err(Error::render(
                format!("linking the {name} program"),
                gl.get_program_info_log(prog),
            ));
        }
        for sh in shaders {
            gl.detach_shader(prog, sh);
            gl.delete_shader(sh);
        }
        Ok(prog)
    }
}
