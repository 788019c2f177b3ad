// Front-to-back traversal of the kd-tree (axis-aligned BSP) built by app/lenslab/render/bsp.py, after
// pbrt-v4's KdTreeAggregate: visit the child on the ray's side of the split first, keep the far child with
// its (t_min, t_max) interval for later, and stop as soon as the nearest hit lies before the next interval.
//
// The far children wait on a short stack (Horn et al. 2007, "Interactive k-D Tree GPU Raytracing") of
// SHORT_STACK entries kept in registers: pushing shifts every entry down one place, so no entry is ever
// addressed by a run-time index. Addressing a local array by a run-time index is slow on SIMD devices, and
// on Mesa's llvmpipe it made a whole Cornell box render 15% slower than this. A push onto a full stack
// drops its deepest entry, the farthest interval; when the stack runs dry before the ray's interval is
// covered, traversal restarts at the root for what is left (kd-restart, Foley and Sugerman 2005).
//
// A plane crossed exactly at an end of the current interval sends the ray to both children (one of them
// for an interval of zero length), as in pbrt. In float arithmetic two distinct planes can give the same t:
// a floor rotated into place lies at y = 1e-16 and y = 7e-17, and a ray reaching the second plane "at t0"
// may still be on the first child's side there. Choosing one child at an exact tie lost such floors
// (validation scene environment_depths, 10% too dark).

#ifndef SHORT_STACK
#define SHORT_STACK 4
#endif

// Test one primitive against the ray and keep it in hit if it lies nearer than hit.t (and is not cut out
// there by a mask): the one step both ways of tracing below take per primitive. Returns whether it was kept.
bool keep_if_nearer(Ray ray, int prim, float t_min, inout Hit hit) {
    vec2 bary;
    float t = intersect_prim(ray, prim, t_min, hit.t, bary);
    bool nearer = t < hit.t;
#if defined(MASKED_TRAVERSAL) && HAS_MATERIAL(MATERIAL_MASK)
    nearer = nearer && !passes_through(ray, prim, t, bary);  // a cut-out (mask.glsl)
#endif
    if (nearer) {
        hit.t = t;
        hit.prim = prim;
        hit.uv = bary;
    }
    return nearer;
}

// Walk the tree whose root is node `root` and whose box is [box_min, box_max] for a hit nearer than hit.t (and
// beyond t_min), keeping it in hit; with any_hit, stop at the first hit found (shadow rays). Returns whether a
// hit was kept. The world's tree and each mesh group's (in its own space) are walked alike.
bool walk_tree(Ray ray, int root, vec3 box_min, vec3 box_max, float t_min, bool any_hit, inout Hit hit) {
    // A zero direction component gives +-huge rather than inf, so no 0 * inf = NaN appears below.
    vec3 inv_dir = 1.0 / mix(ray.d, vec3(1e-30), equal(ray.d, vec3(0.0)));
    vec2 span = intersect_box(ray, inv_dir, box_min, box_max);
    float t0 = max(span.x, t_min);
    float t_end = min(span.y, hit.t);
    if (t0 > t_end) return false;
    bool kept = false;
    float t1 = t_end;

    int stack_node[SHORT_STACK];
    vec2 stack_span[SHORT_STACK];
    int depth = 0;  // entries on the stack
    int node = root;
    float restarted_at = -1.0;
    // After a restart that made no progress (the zero-length intervals of ties at t0 filled the stack and
    // pushed out what lies beyond), ties at t0 go to the far side only: the near sides were just visited.
    bool past_ties = false;
    while (true) {
        // Down to a leaf, in a loop of its own ("while-while", Aila and Laine 2009): lanes in lockstep then
        // descend together instead of each interior step also paying for the leaf code below.
        uvec2 n = kd_nodes[node];
        while ((n.y & 3u) != uint(KD_LEAF)) {  // the low two bits: the split axis, or KD_LEAF
            uint axis = n.y & 3u;
            float split = uintBitsToFloat(n.x);
            float t_plane = (split - ray.o[axis]) * inv_dir[axis];
            // Points exactly on the plane belong to the above child (bsp.py), and so does a ray lying in it.
            bool below_first = ray.o[axis] < split || (ray.o[axis] == split && ray.d[axis] < 0.0);
            int below = node + 1;
            int above = int(n.y >> 2);
            int first = below_first ? below : above;
            int second = below_first ? above : below;
            // Which children the interval [t0, t1] meets: the near one only, the far one only, or both (the
            // far one waits on the stack). The child is chosen by a select, not in each branch: lanes of a
            // SIMD group rarely agree here, and three branches each taken by some lane cost llvmpipe 7 to 15%
            // more on the large scenes (docs/performance.md).
            bool near_only = t_plane > t1 || t_plane <= 0.0;
            bool far_only = !near_only && (t_plane < t0 || (past_ties && t_plane == t0));
            if (!near_only && !far_only) {
                for (int k = SHORT_STACK - 1; k > 0; k--) {
                    stack_node[k] = stack_node[k - 1];
                    stack_span[k] = stack_span[k - 1];
                }
                stack_node[0] = second;
                stack_span[0] = vec2(t_plane, t1);
                depth = min(depth + 1, SHORT_STACK);
                t1 = t_plane;
            }
            node = far_only ? second : first;
            n = kd_nodes[node];
        }
        past_ties = false;
        int count = int(n.y >> 2);
        int first_ref = int(n.x);
        for (int i = 0; i < count; i++) {
            if (keep_if_nearer(ray, prim_refs[first_ref + i], t_min, hit)) {
                kept = true;
                if (any_hit) return true;
            }
        }
        // Done when the nearest hit lies within this leaf's interval, or the ray's whole interval is covered.
        if (hit.t <= t1 || t1 >= t_end) break;
        if (depth > 0) {
            node = stack_node[0];
            t0 = stack_span[0].x;
            t1 = stack_span[0].y;
            for (int k = 0; k < SHORT_STACK - 1; k++) {
                stack_node[k] = stack_node[k + 1];
                stack_span[k] = stack_span[k + 1];
            }
            depth--;
        } else {
            node = root;  // the stack dropped what lies beyond: restart from the root there
            past_ties = t1 == restarted_at;
            restarted_at = t1;
            t0 = t1;
            t1 = t_end;
        }
    }
    return kept;
}

void no_hit_yet(float t_max, out Hit hit) {
    hit.t = t_max;
    hit.prim = NO_HIT;
    hit.uv = vec2(0.0);
    hit.instance = NO_INSTANCE;
}

// Nearest hit with t in (t_min, t_max) among the world's own primitives; with any_hit, stop at the first.
bool trace_bsp(Ray ray, float t_min, float t_max, bool any_hit, out Hit hit) {
    no_hit_yet(t_max, hit);
    return walk_tree(ray, world_root, scene_min, scene_max, t_min, any_hit, hit);
}

// Every primitive of the world's own, in one loop (they are few: render/features.py's FLAT_MAX_PRIMITIVES; with
// instances, the world's primitives follow the mesh groups' triangles, from row first_world_prim).
// The loop counter is the same in every lane, so each primitive is read once for all lanes and no lane waits
// on another's path through a tree: on llvmpipe that is faster than the kd-tree up to a few dozen
// primitives (docs/performance.md). No early exit for shadow rays: a break taken by some lanes only would
// make the loop divergent, and the few tests it would save cost less than that.
bool trace_all_primitives(Ray ray, float t_min, float t_max, out Hit hit) {
    no_hit_yet(t_max, hit);
    for (int i = 0; i < FLAT_PRIMITIVES; i++) keep_if_nearer(ray, first_world_prim + i, t_min, hit);
    return hit.prim != NO_HIT;
}

#if HAS_INSTANCES
// Enter instance k: take the ray into its group's space (the direction is not renormalised, so that t measures
// the same distance in both spaces and hits compare across instances) and walk the group's tree there.
bool enter_instance(Ray ray, int k, float t_min, bool any_hit, inout Hit hit) {
    int row = INSTANCE_ROWS * k;
    vec4 r0 = instances[row], r1 = instances[row + 1], r2 = instances[row + 2];
    Ray local = Ray(vec3(dot(r0.xyz, ray.o) + r0.w, dot(r1.xyz, ray.o) + r1.w, dot(r2.xyz, ray.o) + r2.w),
                    vec3(dot(r0.xyz, ray.d), dot(r1.xyz, ray.d), dot(r2.xyz, ray.d)));
    vec4 box_min = instances[row + 3], box_max = instances[row + 4];
    if (!walk_tree(local, floatBitsToInt(box_min.w), box_min.xyz, box_max.xyz, t_min, any_hit, hit)) return false;
    hit.instance = k;
    return true;
}

// The instances' own kd-tree, over their world boxes (render/instancing.py; built when a scene has many): every
// leaf the ray's interval crosses, nearest first, each of its instances entered, until the nearest hit lies before
// what is left. A plain stack of INSTANCE_TREE_DEPTH entries (the tree is built no deeper); an instance in several
// leaves is entered again only when another leaf came between.
bool walk_instance_tree(Ray ray, float t_min, bool any_hit, inout Hit hit) {
    vec3 inv_dir = 1.0 / mix(ray.d, vec3(1e-30), equal(ray.d, vec3(0.0)));
    vec2 span = intersect_box(ray, inv_dir, instances_min, instances_max);
    float t0 = max(span.x, t_min);
    float t1 = min(span.y, hit.t);
    if (t0 > t1) return false;
    int stack_node[INSTANCE_TREE_DEPTH];
    vec2 stack_span[INSTANCE_TREE_DEPTH];
    int depth = 0;
    int node = instance_root;
    int last = -1;
    bool kept = false;
    while (true) {
        uvec2 n = kd_nodes[node];
        if ((n.y & 3u) != uint(KD_LEAF)) {
            uint axis = n.y & 3u;
            float split = uintBitsToFloat(n.x);
            float t_plane = (split - ray.o[axis]) * inv_dir[axis];
            bool below_first = ray.o[axis] < split || (ray.o[axis] == split && ray.d[axis] < 0.0);
            int first = below_first ? node + 1 : int(n.y >> 2);
            int second = below_first ? int(n.y >> 2) : node + 1;
            if (t_plane > t1 || t_plane <= 0.0) {
                node = first;
            } else if (t_plane < t0) {
                node = second;
            } else {  // both, the far one later (a plane crossed exactly at an end visits both, as bsp.glsl does)
                stack_node[depth] = second;
                stack_span[depth] = vec2(t_plane, t1);
                depth++;
                node = first;
                t1 = t_plane;
            }
            continue;
        }
        int count = int(n.y >> 2);
        int first_ref = int(n.x);
        for (int i = 0; i < count; i++) {
            int k = prim_refs[first_ref + i];
            if (k != last && enter_instance(ray, k, t_min, any_hit, hit)) {
                kept = true;
                if (any_hit) return true;
            }
            last = k;
        }
        if (depth == 0) break;
        depth--;
        node = stack_node[depth];
        t0 = stack_span[depth].x;
        t1 = min(stack_span[depth].y, hit.t);
        if (t0 > t1) break;  // the nearest interval left lies beyond the nearest hit: so does everything else
    }
    return kept;
}

// Two levels (docs/architecture.md, "Two levels"): the world's own primitives, then the instances of mesh groups.
// A few instances (a product shot's large meshes) are entered in one loop that every lane runs alike; a ray that
// misses an instance's box pays for one box test. Many are found through their own tree (instance_root >= 0).
bool trace_instances(Ray ray, float t_min, float t_max, bool any_hit, out Hit hit) {
#if FLAT_PRIMITIVES > 0
    // The world's own primitives are few (the large meshes are the instances): one loop, as in a small scene.
    trace_all_primitives(ray, t_min, t_max, hit);
    if (any_hit && hit.prim != NO_HIT) return true;
#else
    no_hit_yet(t_max, hit);
    if (walk_tree(ray, world_root, scene_min, scene_max, t_min, any_hit, hit) && any_hit) return true;
#endif
    if (instance_root >= 0) {
        walk_instance_tree(ray, t_min, any_hit, hit);
    } else {
        for (int k = 0; k < instance_count; k++) {
            if (enter_instance(ray, k, t_min, any_hit, hit) && any_hit) return true;
        }
    }
    return hit.prim != NO_HIT;
}
#endif

// Nearest hit with t in (t_min, t_max), through the kd-tree (and the instances' trees) or, in a small scene,
// by testing everything.
bool trace_scene(Ray ray, float t_min, float t_max, bool any_hit, out Hit hit) {
#if HAS_INSTANCES
    return trace_instances(ray, t_min, t_max, any_hit, hit);
#elif FLAT_PRIMITIVES > 0
    return trace_all_primitives(ray, t_min, t_max, hit);
#else
    return trace_bsp(ray, t_min, t_max, any_hit, hit);
#endif
}

bool occluded(Ray ray, float t_max) {
    Hit hit;
    return trace_scene(ray, 0.0, t_max, true, hit);
}
