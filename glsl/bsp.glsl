// Front-to-back traversal of the kd-tree (axis-aligned BSP) built by app/lenslab/render/bsp.py, after
// pbrt-v4's KdTreeAggregate: visit the child on the ray's side of the split first, keep the far child on a
// small stack with its (t_min, t_max) interval, and stop as soon as the nearest hit lies before the next
// interval. KD_STACK_SIZE is the tree's depth, fixed when the tree is built.

// Nearest hit with t in (t_min, t_max); with any_hit, stop at the first hit found (shadow rays).
bool trace_bsp(Ray ray, float t_min, float t_max, bool any_hit, out Hit hit) {
    hit.t = t_max;
    hit.prim = NO_HIT;
    hit.uv = vec2(0.0);
    // A zero direction component gives +-huge rather than inf, so no 0 * inf = NaN appears below.
    vec3 inv_dir = 1.0 / mix(ray.d, vec3(1e-30), equal(ray.d, vec3(0.0)));
    vec2 span = intersect_box(ray, inv_dir, scene_min, scene_max);
    float t0 = max(span.x, t_min);
    float t1 = min(span.y, t_max);
    if (t0 > t1) return false;

    int stack_node[KD_STACK_SIZE];
    vec2 stack_span[KD_STACK_SIZE];
    int sp = 0;
    int node = 0;
    while (true) {
        // Down to a leaf, in a loop of its own ("while-while", Aila and Laine 2009): lanes in lockstep then
        // descend together instead of each interior step also paying for the leaf code below.
        uvec2 n = kd_nodes[node];
        while ((n.y & 3u) != 3u) {
            uint axis = n.y & 3u;
            float split = uintBitsToFloat(n.x);
            float t_plane = (split - ray.o[axis]) * inv_dir[axis];
            // Points exactly on the plane belong to the above child (bsp.py), and so does a ray lying in it.
            bool below_first = ray.o[axis] < split || (ray.o[axis] == split && ray.d[axis] < 0.0);
            int below = node + 1;
            int above = int(n.y >> 2);
            int first = below_first ? below : above;
            int second = below_first ? above : below;
            if (t_plane > t1 || t_plane <= 0.0) {
                node = first;
            } else if (t_plane < t0) {
                node = second;
            } else {
                stack_node[sp] = second;
                stack_span[sp] = vec2(t_plane, t1);
                sp++;
                node = first;
                t1 = t_plane;
            }
            n = kd_nodes[node];
        }
        int count = int(n.y >> 2);
        int first_ref = int(n.x);
        for (int i = 0; i < count; i++) {
            int prim = prim_refs[first_ref + i];
            vec2 bary;
            float t = intersect_prim(ray, prim, t_min, hit.t, bary);
            if (t < hit.t) {
                hit.t = t;
                hit.prim = prim;
                hit.uv = bary;
                if (any_hit) return true;
            }
        }
        // The next far child whose interval starts before the nearest hit so far; the rest hold nothing nearer.
        bool more = false;
        while (sp > 0) {
            sp--;
            node = stack_node[sp];
            t0 = stack_span[sp].x;
            t1 = stack_span[sp].y;
            if (t0 <= hit.t) {
                more = true;
                break;
            }
        }
        if (!more) break;
    }
    return hit.prim != NO_HIT;
}

bool occluded(Ray ray, float t_max) {
    Hit hit;
    return trace_bsp(ray, 0.0, t_max, true, hit);
}
