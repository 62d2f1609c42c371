#version 450
// Engine self-test: writes the push-constant value.
layout(push_constant) uniform Push { float value; } pc;
layout(location = 0) out float color;
void main() { color = pc.value; }
