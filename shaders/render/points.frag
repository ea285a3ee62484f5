#version 450
// Points are flat squares of the vertex colour; the RGBA8 value written is the one read.
layout(location = 0) in vec4 v_color;
layout(location = 0) out vec4 o_color;

void main() { o_color = v_color; }
