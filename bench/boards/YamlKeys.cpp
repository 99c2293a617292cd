#include "boards/YamlKeys.hpp"

#include <set>
#include <vector>

#include "core/Errors.hpp"
#include "core/InputFile.hpp"

namespace avrbench {
namespace {

// One walk over the tree as the bench will see it (aliases expanded),
// stopping at the first problem.
class Walk {
public:
    explicit Walk(const std::string& path) : path_(path) {}

    void visit(const YAML::Node& node) {
        if (++nodes_ > kMaxYamlNodes) {
            throw BadInput(yaml_where(path_, node) + ": the YAML expands to more than " + std::to_string(kMaxYamlNodes) +
                           " nodes (aliases of aliases?); a board or scenario has a few hundred");
        }
        for (const YAML::Node& ancestor : ancestors_) {
            if (ancestor.is(node)) {
                throw BadInput(yaml_where(path_, node) + ": a YAML alias refers to a node that contains it (a cycle)");
            }
        }
        if (ancestors_.size() >= kMaxYamlDepth) {
            throw BadInput(yaml_where(path_, node) + ": YAML nested more than " + std::to_string(kMaxYamlDepth) + " levels deep");
        }
        if (!node.IsSequence() && !node.IsMap()) return;
        ancestors_.push_back(node);
        if (node.IsSequence()) {
            for (const auto& item : node) visit(item);
        } else {
            std::set<std::string> seen;
            for (const auto& kv : node) {
                const std::string where = yaml_where(path_, kv.first);
                if (!kv.first.IsScalar()) throw BadInput(where + ": a key must be a single value");
                if (!seen.insert(kv.first.Scalar()).second) throw BadInput(where + ": duplicate key " + quoted_text(kv.first.Scalar()));
                visit(kv.second);
            }
        }
        ancestors_.pop_back();
    }

private:
    const std::string& path_;
    std::size_t nodes_ = 0;
    std::vector<YAML::Node> ancestors_;
};

}  // namespace

std::string yaml_where(const std::string& path, const YAML::Node& node) {
    const auto mark = node.Mark();
    return escaped(path) + ":" + std::to_string(mark.line >= 0 ? mark.line + 1 : 0);
}

YAML::Node load_yaml(const std::string& text, const std::string& path) {
    YAML::Node root;
    try {
        root = YAML::Load(text);
    } catch (const YAML::Exception& e) {
        throw BadInput(escaped(path) + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + escaped(e.msg));
    }
    Walk(path).visit(root);
    return root;
}

void check_unique_keys(const YAML::Node& node, const std::string& path) { Walk(path).visit(node); }

std::string yaml_scalar(const YAML::Node& node, const std::string& path, const std::string& what) {
    if (!node.IsScalar()) throw BadInput(yaml_where(path, node) + ": " + what + " must be a single value");
    return node.Scalar();
}

}  // namespace avrbench
