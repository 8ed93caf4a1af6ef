#include "document/settings_store.hpp"

#include "culling/core/errors.hpp"

#include <QSettings>

namespace lcui {

lc::CullSettings readCullSettings(QSettings& st, lc::CullSettings base) {
    lc::Camera scratch;
    st.beginGroup("params");
    for (const auto& p : lc::cullParams()) {
        const QString key = QString::fromStdString(p.name);
        if (!st.contains(key)) continue;
        try {
            lc::setParam(base, scratch, p.name, st.value(key).toString().toStdString());
        } catch (const lc::Error&) {
        }
    }
    st.endGroup();
    return base;
}

void writeCullSettings(QSettings& st, const lc::CullSettings& s) {
    lc::Camera scratch;
    st.beginGroup("params");
    for (const auto& p : lc::cullParams())
        st.setValue(QString::fromStdString(p.name), QString::fromStdString(lc::getParam(s, scratch, p.name)));
    st.endGroup();
}

} // namespace lcui
