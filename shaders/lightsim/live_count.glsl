// The live patch count of the list (lightsim/live_count.h, LiveCount): the histogram pyramid's top
// texel as the last build left it (or the count uploaded for the first list). Its four components
// are integers float holds exactly; their sum is the count. The passes that read it are drawn over
// at least that many slots and skip the rest.
uniform sampler2D uLiveCount;

int liveCount() {
  ivec4 top = ivec4(texelFetch(uLiveCount, ivec2(0), 0));
  return (top.x + top.y) + (top.z + top.w);
}
