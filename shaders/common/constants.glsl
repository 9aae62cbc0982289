// Shared constants. Include as: #include "common/constants.glsl"
const float PI = 3.14159265358979323846;
const float TWO_PI = 6.28318530717958647692;
const float INV_PI = 0.31830988618379067154;
const float INV_FOUR_PI = 0.07957747154594766788;
